"""Looking at a robot and its cell: the robot's real shape (:mod:`studies.view.meshes`), the mapping of
a URDF's bodies onto a bundled arm's (:mod:`studies.view.mapping`) and the self-contained HTML view
(:mod:`studies.view.html`)."""
