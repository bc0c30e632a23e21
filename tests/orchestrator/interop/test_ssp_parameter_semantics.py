"""SSP 1.0, 5.2.3 (ParameterBindings) and the SSP files other tools write, on SSPs built here.

The standard's text: "When no parameter mapping is specified as part of the binding,
then all the parameter values provided by the parameter source are applied using
their original names. If a parameter matching this name is found in the system, the
parameter value is applied. Otherwise that parameter value is ignored. When a
parameter mapping is specified as part of the binding, then only the mapped
parameter values are applied, using their mapped-to names. Non-mapped parameter
values are not applied in this case."

The FMU is the Reference-FMU Feedthrough: every output equals its input of the
same type (``Float64_continuous_output = Float64_continuous_input``, start values:
Real 0, Integer 0, Boolean false, Enumeration 1).
"""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import SspError
from orchestrator.interop.ssp import import_ssp
from tests.helpers.scenarios import dtcosim
from tests.helpers.ssp_documents import SSC, SSM, SSV, feedthrough, inline_values, real, ssd, write_ssp

PORTS = real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")
TYPED = ('<ssd:Connector name="Int32_input" kind="input"><ssc:Integer/></ssd:Connector>'
         '<ssd:Connector name="Int32_output" kind="output"><ssc:Integer/></ssd:Connector>'
         '<ssd:Connector name="Enumeration_input" kind="input"><ssc:Enumeration name="Option"/></ssd:Connector>'
         '<ssd:Connector name="Enumeration_output" kind="output"><ssc:Enumeration name="Option"/></ssd:Connector>'
         '<ssd:Connector name="Boolean_output" kind="output"><ssc:Boolean/></ssd:Connector>')


def run(folder: Path):
    outcome = CoSimulation(resolve_system(import_ssp(folder))).run(handle_sigint=False)
    assert outcome.complete, outcome.error
    return outcome


def ssv(*params: tuple[str, str, str]) -> str:
    body = "".join(f'<ssv:Parameter name="{n}"><ssv:{t} value="{v}"/></ssv:Parameter>' for n, t, v in params)
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet xmlns:ssv="{SSV}" xmlns:ssc="{SSC}" '
            f'version="1.0" name="set">\n<ssv:Parameters>{body}</ssv:Parameters>\n</ssv:ParameterSet>\n')


def ssm(*entries: tuple[str, str, str]) -> str:
    body = "\n".join(f'  <ssm:MappingEntry source="{s}" target="{t}">{x}</ssm:MappingEntry>' for s, t, x in entries)
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<ssm:ParameterMapping xmlns:ssm="{SSM}" xmlns:ssc="{SSC}" '
            f'version="1.0">\n{body}\n</ssm:ParameterMapping>\n')


FILE_BINDING = """
      <ssd:ParameterBindings>
        <ssd:ParameterBinding source="values.ssv">{mapping}</ssd:ParameterBinding>
      </ssd:ParameterBindings>"""


def one_feedthrough(tmp_path: Path, values: str, mapping: str | None) -> Path:
    binding = FILE_BINDING.format(mapping='<ssd:ParameterMapping source="mapping.ssm"/>' if mapping else "")
    system = (f'<ssd:System name="top"><ssd:Elements>{feedthrough("a", PORTS + TYPED, binding)}'
              '</ssd:Elements></ssd:System>')
    files = {"values.ssv": values} | ({"mapping.ssm": mapping} if mapping else {})
    return write_ssp(tmp_path, ssd(system), files)


# ------------------------------------------------------------------ mappings

def test_one_source_feeds_two_targets_each_through_its_own_linear_transformation(tmp_path):
    # as OMSimulator's LinearTransformation3: k = 2 -> u = 2 k + 10 = 14 and the parameter 4 k + 5 = 13
    folder = one_feedthrough(tmp_path, ssv(("k", "Real", "2.0")), ssm(
        ("k", "Float64_continuous_input", '<ssc:LinearTransformation factor="2" offset="10"/>'),
        ("k", "Float64_fixed_parameter", '<ssc:LinearTransformation factor="4" offset="5"/>')))
    scenario = import_ssp(folder)
    assert dict(scenario.component("a").parameters) == {"Float64_continuous_input": 14.0,
                                                         "Float64_fixed_parameter": 13.0}
    assert np.all(run(folder).column("a.Float64_continuous_output") == 14.0)


def test_with_a_mapping_only_the_mapped_values_apply_and_the_others_are_reported(tmp_path):
    values = ssv(("k", "Real", "2.0"), ("Float64_continuous_input", "Real", "99.0"), ("Int32_input", "Integer", "7"),
                 ("Boolean_input", "Boolean", "true"))
    folder = one_feedthrough(tmp_path, values, ssm(("k", "Float64_continuous_input", "")))
    notes: list[str] = []
    scenario = import_ssp(folder, report=notes.append)
    # k under its mapped-to name; the parameter named like the input itself (99) is not mapped: not applied
    assert dict(scenario.component("a").parameters) == {"Float64_continuous_input": 2.0}
    unmapped = [n for n in notes if "without a mapping entry are not applied (SSP 1.0, 5.2.3)" in n]
    assert len(unmapped) == 1 and all(f"{name} (" in unmapped[0]
                                      for name in ("Float64_continuous_input", "Int32_input", "Boolean_input"))
    assert re.match(r".*SystemStructure\.ssd, line \d+: the binding", unmapped[0])
    outcome = run(folder)
    assert np.all(outcome.column("a.Float64_continuous_output") == 2.0)
    assert np.all(outcome.column("a.Int32_output") == 0) and np.all(outcome.column("a.Boolean_output") == 0)


def test_without_a_mapping_every_value_applies_under_its_own_name(tmp_path):
    folder = one_feedthrough(tmp_path, ssv(("Float64_continuous_input", "Real", "99.0"),
                                           ("Int32_input", "Integer", "7")), None)
    outcome = run(folder)
    assert np.all(outcome.column("a.Float64_continuous_output") == 99.0) and np.all(outcome.column("a.Int32_output") == 7)


@pytest.mark.parametrize("empty", ['source=""', 'target=""'])
def test_a_mapping_entry_with_an_empty_end_is_reported_and_skipped(tmp_path, empty):
    mapping = ssm(("k", "Float64_continuous_input", ""), ("k", "Int32_input", "")).replace(
        'source="k" target="Int32_input"', 'source="" target="Int32_input"' if empty == 'source=""'
        else 'source="k" target=""')
    folder = one_feedthrough(tmp_path, ssv(("k", "Real", "3.0")), mapping)
    notes: list[str] = []
    scenario = import_ssp(folder, report=notes.append)
    assert dict(scenario.component("a").parameters) == {"Float64_continuous_input": 3.0}
    line = next(i for i, row in enumerate(mapping.splitlines(), 1) if empty in row)
    side = empty.split("=")[0]
    assert any(re.search(rf"mapping\.ssm, line {line}: <ssm:MappingEntry> has an empty {side}: it maps no parameter "
                         r"and is skipped", n) for n in notes), notes


# ------------------------------------------------------------------ names that reach nothing

UNCONNECTED = """
  <ssd:System name="top">
    <ssd:Connectors>{root_connectors}</ssd:Connectors>
    <ssd:Elements>{a}
      <ssd:System name="empty"><ssd:Connectors>{empty_connector}</ssd:Connectors></ssd:System>
    </ssd:Elements>{system_binding}
  </ssd:System>"""


def test_parameter_names_that_reach_no_variable_are_ignored_and_listed_in_the_summary(tmp_path):
    system = UNCONNECTED.format(
        root_connectors=real("dangling", "input"),
        a=feedthrough("a", PORTS, inline_values(("Float64_continuous_input", "Real", "4.0"),
                                                ("no_such_variable", "Real", "1.0"))),
        empty_connector=real("p", "parameter"),
        system_binding=inline_values(("dangling", "Real", "1.0"), ("empty.p", "Real", "2.0"),
                                     ("nothing", "Real", "3.0")))
    folder = write_ssp(tmp_path / "ssp", ssd(system))
    notes: list[str] = []
    scenario = import_ssp(folder, report=notes.append)
    ignored = [n for n in notes if n.startswith("parameter value ignored (SSP 1.0, 5.2.3")]
    assert len(ignored) == 4, notes
    for name, why in [("dangling", "connector 'dangling' of system 'top' is connected to no FMU variable"),
                      ("empty.p", "connector 'p' of system 'empty' is connected to no FMU variable"),
                      ("nothing", "neither a connector of system 'top' nor element.name of one of its elements"),
                      ("no_such_variable", "resources/Feedthrough.fmu (Feedthrough) has no variable "
                                           "'no_such_variable'")]:
        assert any(re.search(rf"{re.escape(name)} \([^)]*SystemStructure\.ssd, line \d+\): {re.escape(why)}", n) for n in ignored), \
            (name, ignored)
    assert dict(scenario.component("a").parameters) == {"Float64_continuous_input": 4.0}
    proc = dtcosim("run", str(folder), "--no-plots", "--quiet", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert [n for n in summary["import_notes"] if n.startswith("parameter value ignored")] == ignored
    assert "parameter value ignored" in proc.stderr


# ------------------------------------------------------------------ what other tools write

SYSTEM_CONNECTORS = """
  <ssd:System name="top">
    <ssd:Connectors>{connectors}</ssd:Connectors>
    <ssd:Elements>{a}</ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="" startConnector="in" endElement="a" endConnector="Float64_continuous_input">
        <ssc:LinearTransformation factor="3"/>
      </ssd:Connection>
      <ssd:Connection startElement="a" startConnector="Float64_continuous_output" endElement="" endConnector="out"/>
    </ssd:Connections>{binding}
  </ssd:System>"""


def test_an_empty_start_or_end_element_means_the_systems_own_connector(tmp_path):
    system = SYSTEM_CONNECTORS.format(connectors=real("in", "input") + real("out", "output"),
                                      a=feedthrough("a", PORTS), binding=inline_values(("in", "Real", "1.5")))
    folder = write_ssp(tmp_path, ssd(system))
    scenario = import_ssp(folder)
    # the system's input "in" is set to 1.5 and reaches a's input through factor 3
    assert dict(scenario.component("a").parameters) == {"Float64_continuous_input": 4.5}
    assert np.all(run(folder).column("a.Float64_continuous_output") == 4.5)


TYPED_LINK = """
  <ssd:System name="top">
    <ssd:Elements>{a}{b}</ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="{out}" endElement="b" endConnector="{inp}"/>
    </ssd:Connections>
  </ssd:System>"""


@pytest.mark.parametrize("out, inp, value, result", [
    ("Int32_output", "Enumeration_input", ("Int32_input", "Integer", "2"), "Enumeration_output"),
    ("Enumeration_output", "Int32_input", ("Enumeration_input", "Enumeration", "Option 2"), "Int32_output"),
])
def test_an_integer_and_an_enumeration_connector_connect(tmp_path, out, inp, value, result):
    system = TYPED_LINK.format(a=feedthrough("a", TYPED, inline_values(value)), b=feedthrough("b", TYPED),
                               out=out, inp=inp)
    outcome = run(write_ssp(tmp_path, ssd(system)))
    assert np.all(outcome.column(f"b.{result}") == 2)  # item "Option 2" is 2 in the Feedthrough's type Option


def test_other_different_types_are_refused_with_the_rule_and_the_remedy(tmp_path):
    system = TYPED_LINK.format(a=feedthrough("a", TYPED), b=feedthrough("b", PORTS),
                               out="Boolean_output", inp="Float64_continuous_input")
    document = ssd(system)
    line = next(i for i, row in enumerate(document.splitlines(), 1) if "<ssd:Connection " in row)
    with pytest.raises(SspError, match=rf"line {line}: <ssd:Connection> joins a Boolean and a Real connector \(SSP "
                                       r"1\.0: connected connectors have the same type; Enumeration's is Integer\); "
                                       r"connect connectors of one type"):
        import_ssp(write_ssp(tmp_path, document))


NO_FMU = """
  <ssd:System name="top">
    <ssd:Connectors>{connectors}</ssd:Connectors>
    <ssd:Elements>{elements}</ssd:Elements>
  </ssd:System>"""


@pytest.mark.parametrize("elements, held", [
    ("", "it has no ssd:Component at all"),
    ('<ssd:Component name="sub" source="resources/sub.ssp" type="application/x-ssp-package"/>',
     "its 1 component(s) are of type application/x-ssp-package"),
])
def test_an_archive_without_any_fmu_says_so_first(tmp_path, elements, held):
    # the SSD also holds an element dtcosim does not support: the missing FMUs are said first
    document = ssd(NO_FMU.format(connectors=real("x", "input"), elements=elements),
                   extra="").replace("</ssd:Elements>", "</ssd:Elements><ssd:SignalDictionaries/>")
    archive = tmp_path / "nofmu.ssp"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("SystemStructure.ssd", document)
    with pytest.raises(SspError, match=rf"^{re.escape(str(archive))}: holds no FMU: SystemStructure\.ssd has no "
                                       rf"ssd:Component of type application/x-fmu-sharedlibrary \({re.escape(held)}\)"
                                       r".*nothing to run; add the FMUs"):
        import_ssp(archive)


# ------------------------------------------------------------------ every refusal: element, line, rule, remedy

def _refusal_cases():
    two_ports = PORTS + real("Float64_continuous_input", "input")
    return {
        "duplicate connector": (
            f'<ssd:System name="top"><ssd:Elements>{feedthrough("a", two_ports)}</ssd:Elements></ssd:System>',
            'name="Float64_continuous_input" kind="input"><ssc:Real/></ssd:Connector><ssd:Connector name="Float64_c',
            "ssd:Connector", r"duplicates connector 'Float64_continuous_input' \(SSP 1\.0: connector names are "
                             r"unique in their element\); rename or remove one of them"),
        "unknown element": (
            TYPED_LINK.format(a=feedthrough("a", PORTS), b=feedthrough("b", PORTS), out="Float64_continuous_output",
                              inp="Float64_continuous_input").replace('startElement="a"', 'startElement="c"'),
            'startElement="c"', "ssd:Connection",
            r"startElement 'c' is not an element of system 'top' \(a, b; SSP 1\.0: a connection joins elements of "
            r"its own system\); name one of these elements, or leave startElement out"),
        "unsupported element": (
            f'<ssd:System name="top"><ssd:Elements>{feedthrough("a", PORTS)}</ssd:Elements>'
            '<ssd:SignalDictionaries/></ssd:System>', "<ssd:SignalDictionaries/>", "ssd:SignalDictionaries",
            r"is not supported by dtcosim \(inside <ssd:System> it reads .*\); remove the element or express it"),
        "nested SSP": (
            f'<ssd:System name="top"><ssd:Elements>{feedthrough("a", PORTS)}'
            '<ssd:Component name="s" source="resources/s.ssp" type="application/x-ssp-package"/>'
            '</ssd:Elements></ssd:System>', 'type="application/x-ssp-package"', "ssd:Component",
            r"type 'application/x-ssp-package' is not supported \(dtcosim runs FMUs.*\); export the element as an "
            r"FMU, or copy its system into this SSD"),
        "calculatedParameter driving an input": (
            TYPED_LINK.format(a=feedthrough("a", real("Float64_continuous_input", "input")
                                            + real("calc", "calculatedParameter")),
                              b=feedthrough("b", real("Float64_continuous_input", "input")),
                              out="calc", inp="Float64_continuous_input"),
            'kind="input"><ssc:Real/></ssd:Connector></ssd:Connectors>', "ssd:Connector",
            r"input b\.Float64_continuous_input is driven by calculatedParameter a\.calc: not supported \(dtcosim "
            r"sets inputs from outputs at every step\); connect an output"),
        "linear transformation on an Integer": (
            f'<ssd:System name="top"><ssd:Elements>{feedthrough("a", PORTS, FILE_BINDING)}</ssd:Elements></ssd:System>'
            .replace("{mapping}", '<ssd:ParameterMapping><ssm:ParameterMapping><ssm:MappingEntry source="n" '
                                  'target="Int32_input"><ssc:LinearTransformation factor="2"/></ssm:MappingEntry>'
                                  '</ssm:ParameterMapping></ssd:ParameterMapping>'),
            None, "ssv:Parameter", r"is Integer: a LinearTransformation applies to Real parameters only \(SSP 1\.0\); "
                                   r"use an Integer/Boolean/Enumeration mapping"),
    }


@pytest.mark.parametrize("case", list(_refusal_cases()))
def test_every_refusal_names_the_element_its_line_the_rule_and_the_remedy(tmp_path, case):
    system, marker, element, message = _refusal_cases()[case]
    document = ssd(system)
    files = {"values.ssv": ssv(("n", "Integer", "3"))}
    if marker is None:  # the refused element is in the .ssv file
        where = r"values\.ssv, line 3"
    else:
        line = next(i for i, row in enumerate(document.splitlines(), 1) if marker in row)
        where = rf"SystemStructure\.ssd, line {line}"
    with pytest.raises(SspError, match=rf"{where}: <{element}> {message}"):
        import_ssp(write_ssp(tmp_path, document, files))
