"""Machines from a module catalogue: catalogues of joint, link, base and tool modules and the
connectors they meet by (:mod:`kin.modules.catalogue`, read by :mod:`kin.modules.file`), assemblies
of them made into robots (:mod:`kin.modules.assembly`), and whether each joint holds the rest of the
chain at rest (:mod:`kin.modules.holding`).  docs/modules.md."""
from kin.modules.assembly import MAX_JOINTS, Assembly, AssemblyError, assemble, module_frames
from kin.modules.catalogue import Catalogue, CatalogueError, Connector, Module, Part
from kin.modules.file import bundled_catalogues, catalogue_path, load_catalogue, loads_catalogue
from kin.modules.holding import HoldingReport, gravity_bound, holding

__all__ = ["Assembly", "AssemblyError", "Catalogue", "CatalogueError", "Connector", "HoldingReport", "MAX_JOINTS",
           "Module", "Part", "assemble", "bundled_catalogues", "catalogue_path", "gravity_bound", "holding",
           "load_catalogue", "loads_catalogue", "module_frames"]
