# rsu_sources (filled by its area)
