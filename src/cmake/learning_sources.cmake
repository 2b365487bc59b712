# learning sources (filled by the learning area)
