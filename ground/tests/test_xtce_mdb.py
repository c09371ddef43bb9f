"""The generated XTCE (spec/ccsds/mmic.xtce.xml, `mmic xtce`) read independently with ElementTree
and held to spec/ (the TOML tables, not the Rust code): the TM(3,25) container is the layout of
spec/ccsds/housekeeping.toml in order and size, every ST[8] function is a command whose
arguments have the ranges of spec/ccsds/functions.toml, every TM type of services.toml has a
container. No YAMCS here (test_yamcs_loop.py loads the same file into YAMCS)."""
from __future__ import annotations

import tomllib
import xml.etree.ElementTree as ET

from rust_side import REPO, XTCE, mmic

NS = {"x": "http://www.omg.org/spec/XTCE/20180204"}
SPEC = REPO / "spec" / "ccsds"
HK = tomllib.loads((SPEC / "housekeeping.toml").read_text())
FUNCTIONS = tomllib.loads((SPEC / "functions.toml").read_text())["function"]
ROOT = ET.parse(XTCE).getroot()


def by_name(tag):
    return {e.get("name"): e for e in ROOT.iter(f"{{{NS['x']}}}{tag}")}


def size_bits(t):
    return int(t.find(".//x:IntegerDataEncoding", NS).get("sizeInBits"))


def test_the_committed_xtce_is_what_mmic_generates():
    assert XTCE.read_text() == mmic("xtce").stdout


def test_hk_container_is_the_housekeeping_layout():
    containers = by_name("SequenceContainer")
    params = by_name("Parameter")
    ptypes = {**by_name("IntegerParameterType"), **by_name("EnumeratedParameterType")}
    refs = [e.get("parameterRef") for e in containers["hk-report"].findall("x:EntryList/x:ParameterRefEntry", NS)]
    assert refs == ["hk_sid"] + [p["name"] for p in HK["parameter"]]
    offset = 1
    for p in HK["parameter"]:
        assert p["offset"] == offset
        t = ptypes[params[p["name"]].get("parameterTypeRef")]
        assert size_bits(t) == 8 * p["len"], p["name"]
        if p["unit"] in ("mV", "mA", "us", "0.01 deg"):
            assert [u.text for u in t.findall("x:UnitSet/x:Unit", NS)] == [p["unit"]], p["name"]
        offset += p["len"]
    assert offset == HK["report_len"]
    crit = containers["hk-report"].findall(".//x:Comparison", NS)
    assert {(c.get("parameterRef"), c.get("comparisonOperator", "=="), c.get("value")) for c in crit} == {
        ("ccsds_apid", ">=", "257"), ("ccsds_apid", "<=", "511"), ("service", "==", "3"), ("subservice", "==", "25")}


def test_every_function_is_a_command_with_the_argument_ranges():
    cmds = by_name("MetaCommand")
    atypes = {**by_name("IntegerArgumentType"), **by_name("EnumeratedArgumentType")}
    for f in FUNCTIONS:
        c = cmds[f["name"]]
        assert c.find("x:CommandContainer/x:EntryList/x:FixedValueEntry", NS).get("binaryValue") == f"{f['id']:02x}"
        args = c.findall("x:ArgumentList/x:Argument", NS)
        assert [a.get("name") for a in args] == [a["name"] for a in f["args"]], f["name"]
        for a, spec in zip(args, f["args"]):
            t = atypes[a.get("argumentTypeRef")]
            assert size_bits(t) == (16 if spec["type"] == "u16" else 8)
            r = t.find(".//x:ValidRange", NS)
            if r is not None:
                assert [int(r.get("minInclusive")), int(r.get("maxInclusive"))] == spec["range"], a.get("name")
            else:  # a state: the enumeration covers exactly the range
                values = sorted(int(e.get("value")) for e in t.findall(".//x:Enumeration", NS))
                assert values == list(range(spec["range"][0], spec["range"][1] + 1))


def test_verifiers_are_tied_to_st1_and_fail_on_timeout():
    v = by_name("MetaCommand")["pus-tc"].find("x:VerifierSet", NS)
    stages = [(e.tag.split("}")[1], e.get("name")) for e in v]
    assert stages == [("AcceptedVerifier", None), ("ExecutionVerifier", "Started"),
                      ("CompleteVerifier", None), ("FailedVerifier", None)]
    for e in list(v)[:3]:
        assert e.find(".//x:AncillaryData[@name='yamcs.onTimeout']", NS).text == "FAIL"
    # Algorithms reading TM as instance 1, not BooleanExpression: both race in YAMCS 5.12.8 (issue 24,
    # ground/README.md "quirks").
    for e in v:
        assert e.find("x:CustomAlgorithm/x:AlgorithmText", NS).get("language") == "java-expression"
        tm = {r.get("parameterRef"): r.get("instance")
              for r in e.findall("x:CustomAlgorithm/x:InputSet/x:InputParameterInstanceRef", NS)
              if r.get("parameterRef").startswith("/MMIC/")}
        assert {"/MMIC/service", "/MMIC/subservice", "/MMIC/req_apid", "/MMIC/req_seq_count"} <= tm.keys()
        assert set(tm.values()) == {"1"}, tm
