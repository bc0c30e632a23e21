#!/usr/bin/env python3
"""Build the dtcosim FMUs: ``python build_fmus.py [--out DIR] [--preset table6|table5|table3]``.

Writes WindSource.fmu, Gearbox.fmu and GeneratorRotor.fmu (default: into ``fmus/``
next to this script). The build logic is :mod:`fmus.build` (also ``dtcosim build``).
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fmus.build import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main(default_out=Path(__file__).resolve().parent / "fmus"))
