# mesh import, validation, distance fields, sphere packing, previews
list(APPEND UH_COLLETTE_SOURCES
)
