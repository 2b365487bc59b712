# metrics targets (filled by the metrics area)
