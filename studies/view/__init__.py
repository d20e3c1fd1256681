"""Looking at a robot and its cell: ``rmt view``'s live viewer in viser (:mod:`studies.view.server`, the
scene it draws :mod:`studies.view.scene`, the live values :mod:`studies.view.readouts`, the tool handle
:mod:`studies.view.handle`, path playback :mod:`studies.view.playback` and its plot
:mod:`studies.view.plot`, reach targets :mod:`studies.view.targets`) and the self-contained HTML view
(:mod:`studies.view.html`).  The robot's real shape comes from :mod:`studies.shape`."""
