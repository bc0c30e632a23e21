"""SSP 1.0 documents written in tests: an ``.ssd`` around a system, connectors, Feedthrough components, a folder.

The texts follow the SSP 1.0 standard's schema (and the OSP step annotation); the
components are the Modelica Reference-FMUs (:mod:`tests.helpers.reference_fmus`).
"""

from __future__ import annotations

import shutil
from pathlib import Path

from tests.helpers.reference_fmus import reference_fmu

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSM = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping"
OSP_HTTPS = "https://opensimulationplatform.com/SSP/OSPAnnotations"
OSP_HTTP = "http://opensimulationplatform.com/SSP/OSPAnnotations"


def osp_experiment(step: float = 0.1, stop: float = 1.0, namespace: str = OSP_HTTPS) -> str:
    return f"""
  <ssd:DefaultExperiment startTime="0" stopTime="{stop}">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm xmlns:osp="{namespace}">
          <osp:FixedStepAlgorithm baseStepSize="{step}"/>
        </osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>"""


def ssd(system: str, experiment: str | None = None, extra: str = "") -> str:
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" xmlns:ssv="{SSV}" xmlns:ssm="{SSM}"
    name="test" version="1.0">
{system}
{extra}
{osp_experiment() if experiment is None else experiment}
</ssd:SystemStructureDescription>
"""


def real(name: str, kind: str, unit: str = "") -> str:
    unit_attr = f' unit="{unit}"' if unit else ""
    return f'<ssd:Connector name="{name}" kind="{kind}"><ssc:Real{unit_attr}/></ssd:Connector>'


def feedthrough(name: str, connectors: str, bindings: str = "") -> str:
    return f"""
    <ssd:Component name="{name}" source="resources/Feedthrough.fmu">
      <ssd:Connectors>{connectors}</ssd:Connectors>{bindings}
    </ssd:Component>"""


def inline_values(*params: tuple[str, str, str], prefix: str = "") -> str:
    body = "".join(f'<ssv:Parameter name="{n}"><ssv:{t} value="{v}"/></ssv:Parameter>' for n, t, v in params)
    prefix_attr = f' prefix="{prefix}"' if prefix else ""
    return f"""
      <ssd:ParameterBindings>
        <ssd:ParameterBinding{prefix_attr}>
          <ssd:ParameterValues>
            <ssv:ParameterSet version="1.0" name="set"><ssv:Parameters>{body}</ssv:Parameters></ssv:ParameterSet>
          </ssd:ParameterValues>
        </ssd:ParameterBinding>
      </ssd:ParameterBindings>"""


def write_ssp(folder: Path, text: str, files: dict[str, str] | None = None) -> Path:
    (folder / "resources").mkdir(parents=True, exist_ok=True)
    for name in ("Feedthrough", "Dahlquist"):
        shutil.copy(reference_fmu(name), folder / "resources" / f"{name}.fmu")
    (folder / "SystemStructure.ssd").write_text(text)
    for name, content in (files or {}).items():
        (folder / name).write_text(content)
    return folder


def zip_folder(folder: Path, archive: Path) -> Path:
    """``archive``: an ``.ssp`` holding the files of the SSP folder ``folder`` (relative names with '/')."""
    import zipfile

    with zipfile.ZipFile(archive, "w") as zf:
        for f in sorted(folder.rglob("*")):
            if f.is_file():
                zf.write(f, f.relative_to(folder).as_posix())
    return archive
