"""rmtkit planning: singular error windows, OMPL joint-path planning, path following, timing and
dense path validation.  (Grows with the planning issue; depends on ``kin`` only.)"""
