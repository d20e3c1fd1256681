"""rmtkit benchmarks layer."""
