"""SSP 1.0 files: export (:mod:`.ssp_export`) and import (:mod:`.ssp_import`) of a scenario.

The import reads what other tools write (nested systems, system connectors,
transformations, ``.ssv``/``.ssm`` parameter files, the OSP annotation under both
namespaces; :mod:`.ssp_system`, :mod:`.ssp_parameters`, :mod:`.ssp_xml`) and refuses
what dtcosim does not support naming the element and its line.
"""

from __future__ import annotations

from .ssp_export import PARAMETER_SET, export_ssp, system_structure
from .ssp_import import SSD_NAME, import_ssp, is_ssp, locate_ssd
from .ssp_xml import DTCOSIM_ANNOTATION, NS, OSP_ANNOTATION

__all__ = ["DTCOSIM_ANNOTATION", "NS", "OSP_ANNOTATION", "PARAMETER_SET", "SSD_NAME", "export_ssp", "import_ssp",
           "is_ssp", "locate_ssd", "system_structure"]
