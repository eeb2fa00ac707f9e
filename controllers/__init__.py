"""Semi-active controllers that turn the benchmark's measurements into coil voltages."""
