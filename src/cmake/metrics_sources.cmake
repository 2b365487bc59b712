# metrics sources (filled by the metrics area)
