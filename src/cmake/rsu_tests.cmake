# rsu_tests (filled by its area)
