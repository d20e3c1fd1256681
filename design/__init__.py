"""rmtkit design: workspace and coverage metrics, link-parameter optimisation, sweeps and
surrogates.  (Grows with the design issues; depends on ``planning`` and ``kin``.)"""
