# learning targets (filled by the learning area)
