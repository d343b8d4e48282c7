"""The comparison engine: two sides of one train run, aligned, measured and judged against tolerances."""
