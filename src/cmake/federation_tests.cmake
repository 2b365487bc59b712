# federation_tests (filled by its area)
