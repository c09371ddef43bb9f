"""Build `ccsdspy` packet definitions from a plain field list (so that a generated file can feed them).

A field is (name, byte_offset, bit_offset, data_type, bit_length): the offset of its first bit is
8 * byte_offset + bit_offset from the start of the packet, primary header included (ccsdspy's
convention for `PacketField(bit_offset=...)`); data_type is one of ccsdspy's "uint", "int", "float",
"str", "fill". ground/ccsds/hk-3-25.csv is such a list for TM(3,25) (hand-written for now; the Rust
side will generate it from spec/).
"""
from __future__ import annotations

import csv
from pathlib import Path
from typing import Iterable, NamedTuple

import ccsdspy


class Field(NamedTuple):
    name: str
    byte_offset: int
    bit_offset: int
    data_type: str
    bit_length: int


def fields_from_csv(path: str | Path) -> list[Field]:
    """Read a field list with the header `name,byte_offset,bit_offset,data_type,bit_length`."""
    with open(path, newline="") as f:
        return [Field(r["name"], int(r["byte_offset"]), int(r["bit_offset"]), r["data_type"],
                      int(r["bit_length"])) for r in csv.DictReader(f)]


def fixed_length(fields: Iterable[Field | tuple]) -> ccsdspy.FixedLength:
    """A ccsdspy.FixedLength definition; refuses overlapping fields and fields inside the primary header."""
    fields = sorted((Field(*f) for f in fields), key=lambda f: 8 * f.byte_offset + f.bit_offset)
    end = 48  # the 6-octet primary header, decoded by ccsdspy itself
    packet_fields = []
    for f in fields:
        start = 8 * f.byte_offset + f.bit_offset
        if start < end:
            raise ValueError(f"field {f.name} starts at bit {start}, before bit {end}")
        end = start + f.bit_length
        packet_fields.append(ccsdspy.PacketField(name=f.name, data_type=f.data_type,
                                                 bit_length=f.bit_length, bit_offset=start))
    return ccsdspy.FixedLength(packet_fields)
