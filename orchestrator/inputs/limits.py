"""Size limits of everything a user's input can make dtcosim allocate, checked before anything is allocated.

The numbers are stated in ``docs/orchestrator.md`` and ``docs/studies.md``; each
check raises the file kind's error naming the key, the value and the limit.

=======================  ==============  ==================================================
limit                    value           what it bounds
=======================  ==============  ==================================================
MAX_RESULT_VALUES        100 000 000     samples x recorded variables of one run (800 MB of
                                         float64 in memory, ~2 GB of CSV): an hour of the
                                         paper's 23 variables at 1 kHz fits
MIN_RELATIVE_STEP        1e-9            smallest step relative to max(|start|, |stop|): the
                                         communication points stay distinct and the step
                                         count below 2e9
MAX_LDD_BINS             100 000         load duration distribution bins
MAX_AXIS_VALUES          100 000         values of one study axis (start/stop/num)
MAX_STUDY_POINTS         1 000 000       points of one study (the product of its axes)
MAX_SSP_MEMBERS          10 000          files in an .ssp archive
MAX_SSP_BYTES            1 GiB           uncompressed size of an .ssp archive's content
MAX_SSP_RATIO            200             uncompressed / compressed size of one member
MAX_SSP_XML_BYTES        64 MiB          one .ssd, .ssv or .ssm file (parsed whole)
MAX_FMU_MEMBERS          10 000          files in an FMU archive (also one inside an .ssp)
MAX_FMU_BYTES            1 GiB           uncompressed size of an FMU's content: checked
                                         from its directory and counted while extracting
MAX_FMU_RATIO            200             uncompressed / compressed size of one member
MAX_RECORD_BYTES         256 MiB         a recorded series file (.outb, .out, .csv): read
                                         whole and decoded to float64 (an OpenFAST .outb
                                         grows 4x); 600 s of 100 channels at 80 Hz is 10 MB
MAX_LOOP_ITERATIONS      10 000          fixed-point sweeps of an algebraic loop per
                                         communication point
=======================  ==============  ==================================================

The FMU limits are :data:`fmus.archive_checks.MAX_FMU_MEMBERS`, ``MAX_FMU_BYTES`` and
``MAX_FMU_RATIO`` (the FMU layer checks them; :func:`fmus.archive_checks.layout_problems`).

The number of harmonics of the wind (1 to 100 000) is a model limit:
:data:`components.model.wind.MAX_HARMONICS`.
"""

from __future__ import annotations

MAX_RESULT_VALUES = 100_000_000
MIN_RELATIVE_STEP = 1.0e-9
MAX_LDD_BINS = 100_000
MAX_AXIS_VALUES = 100_000
MAX_STUDY_POINTS = 1_000_000
MAX_SSP_MEMBERS = 10_000
MAX_SSP_BYTES = 1 << 30
MAX_SSP_RATIO = 200
MAX_SSP_XML_BYTES = 64 << 20
MAX_RECORD_BYTES = 256 << 20
MAX_LOOP_ITERATIONS = 10_000
