"""rmtkit studies: bundled studies, reports, the ``rmt`` command line and benchmarks."""
