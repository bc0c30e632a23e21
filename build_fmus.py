#!/usr/bin/env python3
"""Build the dtcosim FMUs from a checkout: ``python build_fmus.py [--out DIR] [--preset table6|table5|table3]``.

The same as ``dtcosim build`` (:mod:`orchestrator.commands.build`): writes the FMUs into
the FMU folder ``dtcosim run`` searches (``$DTCOSIM_FMU_DIR``, else ``fmus/`` in the
per-user cache, ``~/.cache/dtcosim/fmus``) or into ``--out``; never into the checkout.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from orchestrator.commands.cli import end_process, main  # noqa: E402

if __name__ == "__main__":
    end_process(main(["build", *sys.argv[1:]]))
