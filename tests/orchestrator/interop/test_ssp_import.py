"""SSP 1.0 files as other tools write them, written here from the standard's text, with values computed by hand.

The FMUs are the Reference-FMUs: Feedthrough (every output equals its input of
the same type, no state) and Dahlquist (x' = -k x with x(0) = 1, forward Euler
with its own fixed internal step of 0.1 s: x(t) = (1 - 0.1 k)^(t / 0.1) at communication
points that are multiples of 0.1 s).
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError, SspError
from orchestrator.interop.ssp import import_ssp
from tests.helpers.reference_fmus import reference_fmu
from tests.helpers.scenarios import dtcosim
from tests.helpers.ssp_documents import (
    OSP_HTTP,
    SSC,
    SSM,
    SSV,
    feedthrough,
    inline_values,
    osp_experiment,
    real,
    ssd,
    write_ssp,
    zip_folder,
)

def run(folder: Path, **kwargs):
    outcome = CoSimulation(resolve_system(import_ssp(folder, **kwargs))).run(handle_sigint=False)
    assert outcome.complete, outcome.error
    return outcome


A_TO_B = """
  <ssd:System name="top">
    <ssd:Elements>{a}{b}
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="Float64_continuous_output" endElement="b"
                      endConnector="Float64_continuous_input">{transformation}</ssd:Connection>
    </ssd:Connections>
  </ssd:System>"""


def test_a_linear_transformation_on_a_connection_gives_factor_times_value_plus_offset(tmp_path):
    system = A_TO_B.format(
        a=feedthrough("a", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output"),
                      inline_values(("Float64_continuous_input", "Real", "5.0"))),
        b=feedthrough("b", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")),
        transformation='<ssc:LinearTransformation factor="2" offset="3"/>')
    outcome = run(write_ssp(tmp_path, ssd(system)))
    assert np.all(outcome.column("a.Float64_continuous_output") == 5.0)
    assert np.all(outcome.column("b.Float64_continuous_output") == 2 * 5.0 + 3)  # what the receiver saw


SSV_FILE = f"""<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet xmlns:ssv="{SSV}" xmlns:ssc="{SSC}" version="1.0" name="from-file">
  <ssv:Parameters>
    <ssv:Parameter name="gain_in"><ssv:Real value="4.0" unit="km"/></ssv:Parameter>
    <ssv:Parameter name="count"><ssv:Integer value="3"/></ssv:Parameter>
    <ssv:Parameter name="Boolean_input"><ssv:Boolean value="true"/></ssv:Parameter>
    <ssv:Parameter name="Enumeration_input"><ssv:Enumeration value="Option 2"/></ssv:Parameter>
  </ssv:Parameters>
  <ssv:Units>
    <ssc:Unit name="km"><ssc:BaseUnit m="1" factor="1000"/></ssc:Unit>
  </ssv:Units>
</ssv:ParameterSet>
"""
SSM_FILE = f"""<?xml version="1.0" encoding="UTF-8"?>
<ssm:ParameterMapping xmlns:ssm="{SSM}" xmlns:ssc="{SSC}" version="1.0">
  <ssm:MappingEntry source="gain_in" target="Float64_continuous_input">
    <ssc:LinearTransformation factor="10" offset="0.5"/>
  </ssm:MappingEntry>
  <ssm:MappingEntry source="count" target="Int32_input">
    <ssc:IntegerMappingTransformation>
      <ssc:MapEntry source="3" target="30"/>
    </ssc:IntegerMappingTransformation>
  </ssm:MappingEntry>
</ssm:ParameterMapping>
"""


def test_an_ssv_file_with_an_ssm_mapping_and_its_transformations(tmp_path):
    connectors = (real("Float64_continuous_input", "input", "m") + real("Float64_continuous_output", "output", "m")
                  + '<ssd:Connector name="Int32_output" kind="output"><ssc:Integer/></ssd:Connector>'
                  + '<ssd:Connector name="Boolean_output" kind="output"><ssc:Boolean/></ssd:Connector>'
                  + '<ssd:Connector name="Enumeration_output" kind="output"><ssc:Enumeration name="Option"/>'
                    '</ssd:Connector>')
    binding = """
      <ssd:ParameterBindings>
        <ssd:ParameterBinding source="params/values.ssv">
          <ssd:ParameterMapping source="params/mapping.ssm"/>
        </ssd:ParameterBinding>
      </ssd:ParameterBindings>"""
    system = f'<ssd:System name="top"><ssd:Elements>{feedthrough("a", connectors, binding)}</ssd:Elements></ssd:System>'
    units = '<ssd:Units><ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit></ssd:Units>'
    folder = write_ssp(tmp_path, ssd(system, extra=units))
    (folder / "params").mkdir()
    (folder / "params" / "values.ssv").write_text(SSV_FILE)
    (folder / "params" / "mapping.ssm").write_text(SSM_FILE)
    outcome = run(folder)
    # 4 km = 4000 m (the connector's unit), then 10 x + 0.5 (SSP: conversion before the transformation)
    assert np.all(outcome.column("a.Float64_continuous_output") == 10 * 4000.0 + 0.5)
    assert np.all(outcome.column("a.Int32_output") == 30)  # 3 mapped to 30
    # the binding has a mapping: its unmapped values are not applied (SSP 1.0, 5.2.3), the start values stay
    assert np.all(outcome.column("a.Boolean_output") == 0.0)  # start false, not the set's true
    assert np.all(outcome.column("a.Enumeration_output") == 1)  # start 1, not the set's "Option 2"


NESTED = """
  <ssd:System name="top">
    <ssd:Elements>
      <ssd:System name="inner">
        <ssd:Connectors>{inner_out}</ssd:Connectors>
        <ssd:Elements>{source}</ssd:Elements>
        <ssd:Connections>
          <ssd:Connection startElement="src" startConnector="Float64_continuous_output" endConnector="out"/>
        </ssd:Connections>
      </ssd:System>{sink}
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="inner" startConnector="out" endElement="sink" endConnector="Float64_continuous_input">
        <ssc:LinearTransformation factor="-1"/>
      </ssd:Connection>
    </ssd:Connections>
  </ssd:System>"""


def test_a_nested_system_is_flattened_with_its_path_and_connected_through_its_connector(tmp_path):
    system = NESTED.format(
        inner_out=real("out", "output"),
        source=feedthrough("src", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output"),
                           inline_values(("Float64_continuous_input", "Real", "1.25"))),
        sink=feedthrough("sink", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")))
    folder = write_ssp(tmp_path, ssd(system))
    scenario = import_ssp(folder)
    assert scenario.component_names == ["inner-src", "sink"]
    assert [str(c) for c in scenario.connections] == ["inner-src.Float64_continuous_output -> "
                                                      "sink.Float64_continuous_input"]
    outcome = run(folder)
    assert np.all(outcome.column("sink.Float64_continuous_output") == -1.25)


SYSTEM_PARAMETER = """
  <ssd:System name="top">
    <ssd:Elements>
      <ssd:System name="plant">
        <ssd:Connectors><ssd:Connector name="rate" kind="parameter"><ssc:Real/></ssd:Connector></ssd:Connectors>
        <ssd:Elements>
          <ssd:Component name="decay" source="resources/Dahlquist.fmu">
            <ssd:Connectors>
              <ssd:Connector name="k" kind="parameter"><ssc:Real/></ssd:Connector>
              <ssd:Connector name="x" kind="output"><ssc:Real/></ssd:Connector>
            </ssd:Connectors>{component_binding}
          </ssd:Component>
        </ssd:Elements>
        <ssd:Connections>
          <ssd:Connection startConnector="rate" endElement="decay" endConnector="k"/>
        </ssd:Connections>
      </ssd:System>
    </ssd:Elements>{system_binding}
  </ssd:System>"""


@pytest.mark.parametrize("name, prefix", [("plant.rate", ""), ("rate", "plant.")])
def test_a_system_level_binding_on_a_system_connector_wins_over_the_component_level_one(tmp_path, name, prefix):
    system = SYSTEM_PARAMETER.format(component_binding=inline_values(("k", "Real", "1.5")),
                                     system_binding=inline_values((name, "Real", "2.0"), prefix=prefix))
    outcome = run(write_ssp(tmp_path, ssd(system)))
    n = np.arange(len(outcome.time_s))
    np.testing.assert_allclose(outcome.time_s, 0.1 * n)
    # forward Euler with k = 2 (the system's value; SSP: higher levels take precedence), h = 0.1
    np.testing.assert_allclose(outcome.column("plant-decay.x"), (1 - 2.0 * 0.1) ** n, rtol=1e-12)


def test_a_later_binding_at_one_level_wins(tmp_path):
    two = inline_values(("k", "Real", "1.5")).replace("</ssd:ParameterBindings>", "") \
        + inline_values(("k", "Real", "3.0")).replace("<ssd:ParameterBindings>", "")
    system = SYSTEM_PARAMETER.format(component_binding=two, system_binding="")
    outcome = run(write_ssp(tmp_path, ssd(system)))
    n = np.arange(len(outcome.time_s))
    np.testing.assert_allclose(outcome.column("plant-decay.x"), (1 - 3.0 * 0.1) ** n, rtol=1e-12)


def test_the_osp_annotation_under_the_http_namespace_gives_the_step(tmp_path):
    system = SYSTEM_PARAMETER.format(component_binding="", system_binding="")
    outcome = run(write_ssp(tmp_path, ssd(system, osp_experiment(step=0.2, stop=1.0, namespace=OSP_HTTP))))
    np.testing.assert_allclose(outcome.time_s, [0.0, 0.2, 0.4, 0.6, 0.8, 1.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(outcome.column("plant-decay.x"), 0.9 ** (2 * np.arange(6)), rtol=1e-12)  # k = 1


def test_without_an_annotation_the_step_comes_from_the_command_line(tmp_path):
    folder = write_ssp(tmp_path / "ssp", ssd(SYSTEM_PARAMETER.format(component_binding="", system_binding=""),
                                             '<ssd:DefaultExperiment startTime="0" stopTime="1.0"/>'))
    proc = dtcosim("run", str(folder), "--step", "0.2", "--no-plots", "--quiet", "--out", str(tmp_path / "out"),
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    rows = (tmp_path / "out" / "timeseries.csv").read_text().splitlines()
    assert len(rows) == 1 + 6 and float(rows[-1].split(",")[1]) == pytest.approx(0.9 ** 10, rel=1e-12)
    # Dahlquist's own DefaultExperiment stepSize (0.1) is the fallback without --step
    assert import_ssp(folder).simulation.step_s == 0.1


def test_without_any_step_the_error_says_which_option_to_give(tmp_path):
    folder = write_ssp(tmp_path, ssd(SYSTEM_PARAMETER.format(component_binding="", system_binding=""),
                                     "<ssd:DefaultExperiment/>"))
    shutil.copy(reference_fmu("Feedthrough"), folder / "resources" / "Dahlquist.fmu")  # no stepSize, stopTime 2
    with pytest.raises(ScenarioError, match=r"simulation\.step.*give it on the command line: --step H"):
        import_ssp(folder)
    assert import_ssp(folder, step_s=0.5).simulation.stop_s == 2.0  # the FMU's DefaultExperiment stopTime


@pytest.mark.parametrize("element, text", [
    ("ssd:SignalDictionaries", "<ssd:SignalDictionaries/>"),
    ("ssc:Binary", '<ssd:Connector name="bin" kind="input"><ssc:Binary/></ssd:Connector>'),
])
def test_an_unsupported_element_is_refused_naming_it_and_its_line(tmp_path, element, text):
    system = SYSTEM_PARAMETER.format(component_binding="", system_binding="")
    if element == "ssd:SignalDictionaries":
        system = system.replace("</ssd:Elements>\n  </ssd:System>", "</ssd:Elements>\n" + text + "\n  </ssd:System>")
    else:
        system = system.replace('<ssd:Connector name="x" kind="output">', text + '<ssd:Connector name="x" kind="output">')
    document = ssd(system)
    line = next(i for i, row in enumerate(document.splitlines(), 1) if text.split(">")[0].split()[0] in row
                and (element != "ssc:Binary" or "ssc:Binary" in row))
    folder = write_ssp(tmp_path, document)
    with pytest.raises(SspError, match=rf"SystemStructure\.ssd, line {line}: <{element}> is not supported by dtcosim"):
        import_ssp(folder)


def test_an_unknown_parameter_name_is_ignored_and_reported(tmp_path):
    system = SYSTEM_PARAMETER.format(component_binding="", system_binding=inline_values(("plant.nothing", "Real", "1")))
    notes: list[str] = []
    scenario = import_ssp(write_ssp(tmp_path, ssd(system)), report=notes.append)
    assert dict(scenario.component("plant-decay").parameters) == {}
    assert any(re.search(r"ignored \(SSP 1\.0, 5\.2\.3.*plant\.nothing \(.*line \d+\): neither a connector of "
                         r"system 'plant'", n) for n in notes), notes



MAPPINGS = {
    "Boolean": ("Boolean_output", "Boolean_input", "Boolean", "true",
                '<ssc:BooleanMappingTransformation><ssc:MapEntry source="true" target="false"/>'
                '</ssc:BooleanMappingTransformation>', 0.0),
    "Integer": ("Int32_output", "Int32_input", "Integer", "1",
                '<ssc:IntegerMappingTransformation><ssc:MapEntry source="1" target="5"/>'
                '</ssc:IntegerMappingTransformation>', 5.0),
    "Enumeration": ("Enumeration_output", "Enumeration_input", "Enumeration", "Option 1",
                    '<ssc:EnumerationMappingTransformation><ssc:MapEntry source="Option 1" target="Option 2"/>'
                    '</ssc:EnumerationMappingTransformation>', 2.0),
}


@pytest.mark.parametrize("kind", list(MAPPINGS))
def test_mapping_transformations_on_connections(tmp_path, kind):
    out, inp, ssc_type, value, mapping, expected = MAPPINGS[kind]
    ssc_el = f"<ssc:{ssc_type}/>" if kind != "Enumeration" else '<ssc:Enumeration name="Option"/>'
    conn = lambda n, k: f'<ssd:Connector name="{n}" kind="{k}">{ssc_el}</ssd:Connector>'  # noqa: E731
    system = f"""
  <ssd:System name="top">
    <ssd:Elements>{feedthrough("a", conn(inp, "input") + conn(out, "output"), inline_values((inp, ssc_type, value)))}
      {feedthrough("b", conn(inp, "input") + conn(out, "output"))}
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="{out}" endElement="b" endConnector="{inp}">{mapping}</ssd:Connection>
    </ssd:Connections>
  </ssd:System>"""
    outcome = run(write_ssp(tmp_path, ssd(system)))
    assert np.all(outcome.column(f"b.{out}") == expected)


def test_transformations_survive_export_and_import(tmp_path):
    from orchestrator.interop.ssp import export_ssp

    system = A_TO_B.format(
        a=feedthrough("a", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output"),
                      inline_values(("Float64_continuous_input", "Real", "5.0"))),
        b=feedthrough("b", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")),
        transformation='<ssc:LinearTransformation factor="2" offset="3"/>')
    scenario = import_ssp(write_ssp(tmp_path / "in", ssd(system)))
    again = import_ssp(export_ssp(resolve_system(scenario), tmp_path / "out.ssp"))
    assert again.connections == scenario.connections and again.connections[0].transformation is not None
    outcome = CoSimulation(resolve_system(again)).run(handle_sigint=False)
    assert np.all(outcome.column("b.Float64_continuous_output") == 13.0)


def test_other_tools_annotations_are_reported_and_ssd_folder_and_archive_read_alike(tmp_path):
    system = SYSTEM_PARAMETER.format(component_binding="", system_binding="").replace(
        "</ssd:Elements>\n  </ssd:System>",
        '</ssd:Elements>\n<ssd:Annotations><ssc:Annotation type="com.example.layout"><x xmlns="urn:x"/>'
        "</ssc:Annotation></ssd:Annotations>\n  </ssd:System>")
    folder = write_ssp(tmp_path / "folder", ssd(system))
    notes: list[str] = []
    from_folder = import_ssp(folder, report=notes.append)
    assert len(notes) == 1 and "annotation of type 'com.example.layout' ignored" in notes[0] and "line" in notes[0]
    archive = zip_folder(folder, tmp_path / "system.ssp")
    for other in (import_ssp(folder / "SystemStructure.ssd"), import_ssp(archive)):
        assert [c.name for c in other.components] == [c.name for c in from_folder.components]
        assert other.connections == from_folder.connections and other.simulation == from_folder.simulation


def test_another_tools_fmu_is_archived_unchanged_and_named_as_needing_the_parameter_set(tmp_path):
    import zipfile

    from orchestrator.interop.ssp_export import export_ssp, unbaked_components

    system = A_TO_B.format(
        a=feedthrough("a", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output"),
                      inline_values(("Float64_continuous_input", "Real", "5.0"))),
        b=feedthrough("b", real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")),
        transformation="")
    resolved = resolve_system(import_ssp(write_ssp(tmp_path / "in", ssd(system))))
    assert unbaked_components(resolved) == ["a"]  # b has no values; a's value lives in the parameter set only
    out = export_ssp(resolved, tmp_path / "out.ssp")
    with zipfile.ZipFile(out) as archive:
        archived = {n for n in archive.namelist() if n.endswith(".fmu")}
        assert len(archived) == 1  # both components share the unchanged file
        assert archive.read(archived.pop()) == reference_fmu("Feedthrough").read_bytes()
