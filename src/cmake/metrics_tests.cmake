# metrics tests (filled by the metrics area)
