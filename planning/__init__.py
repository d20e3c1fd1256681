"""rmtkit planning: singular error windows (:mod:`planning.windows`), proofs about joint paths
(:mod:`planning.certify`), OMPL joint-path planning (:mod:`planning.ompl`), tool paths
(:mod:`planning.toolpath`), path following (:mod:`planning.follow`), time parameterisation
(:mod:`planning.timing`), path validation (:mod:`planning.validate`), work cells (:mod:`planning.cell`)
and assertions for users' own test suites (:mod:`planning.testing`).  Depends on ``kin`` only."""
