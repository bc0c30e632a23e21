"""Helpers of the study tests: small study files, free ports, the CLI."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

#: a study of the built-in Sec. 4.1 model, 10 ms per run, without axes (tests append them)
MODEL_BASE = """
name = "t"
engine = "monolithic"
measures = ["I_max_acc"]
[base]
model = "sensitivity-variant"
[simulation]
stop = 0.01
"""
#: top-level keys of the small studies: the Sec. 4.1 model, 20 ms per run
SMALL_HEAD = """
name = "small"
engine = "monolithic"
measures = ["I_max_acc", "cpu_time", "steps", "gearbox.stage3.F_mesh:mean"]
"""
#: its base and time grid (tables: after every top-level key)
SMALL_TABLES = """
[base]
model = "sensitivity-variant"

[simulation]
stop = 0.02
output_interval = 1.0e-3
window = [0.01, 0.02]
"""
#: a 2 x 2 design (R1 x stage-3 lambda) as explicit points; the last point's lambda is invalid
SMALL_STUDY = SMALL_HEAD + """
points = [
    { "gearbox.R1" = 8.0, "gearbox.stage3.lambda" = 1.0e5 },
    { "gearbox.R1" = 8.0, "gearbox.stage3.lambda" = 6.0e5 },
    { "gearbox.R1" = 9.0, "gearbox.stage3.lambda" = 1.0e5 },
    { "gearbox.R1" = 9.0, "gearbox.stage3.lambda" = -6.0e5 },
]
""" + SMALL_TABLES
#: the error of the invalid point
SMALL_FAILURE = "invalid parameter stage3.lambda = -600000.0: expected > 0 (within [1e-30, 1e+30])"
#: quasi-static stage-3 mesh force of the 1 kN m output torque: T / (r cos 20 deg), r = 80 mm [N]
STAGE3_FORCE_N = 1000.0 / (0.08 * 0.9396926207859084)


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_cli(*args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run the installed ``dtcosim`` console script."""
    exe = Path(sys.executable).parent / "dtcosim"
    return subprocess.run([str(exe), *args], cwd=cwd, env=dict(os.environ), capture_output=True, text=True,
                          timeout=timeout)
