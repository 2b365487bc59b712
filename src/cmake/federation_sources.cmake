# federation_sources (filled by its area)
