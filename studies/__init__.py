"""rmtkit studies: bundled studies, reports, the ``rmt`` command line and benchmarks.

Its parts depend one way (``tests/test_layers.py`` checks every import):

* the package's own modules, the bottom — units for printing (:mod:`~studies.units`), strict JSON
  (:mod:`~studies.jsonio`), joint paths (:mod:`~studies.jointpath`), task rows
  (:mod:`~studies.taskrows`), published values the studies compare with (:mod:`~studies.published`)
  — and the bundled tool paths (:mod:`~studies.toolpaths`);
* reports (:mod:`~studies.report`) and figures (:mod:`~studies.plots`), on the bottom only;
* the study engine (:mod:`~studies.study`): the context a study writes into, shared sections and the
  helpers studies share, on reports, figures and the bottom;
* the bundled studies (:mod:`~studies.bundled`), plain scripts on the study engine and below;
* the command line (:mod:`~studies.cli`) on top of everything; nothing imports it;
* the benchmarks (:mod:`~studies.benchmarks`), on the bottom only.
"""
