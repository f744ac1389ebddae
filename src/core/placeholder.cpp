// placeholder so the target has a source until the module's first file lands
