# sphere trees, .ist files, queries, collision world
list(APPEND UH_COLLETTE_SOURCES
)
