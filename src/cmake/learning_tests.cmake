# learning tests (filled by the learning area)
