"""Engineering units for OPC UA: a signal's unit text as an `EUInformation` (UNECE Recommendation 20 codes).

OPC UA Part 8 (5.6.3) identifies a unit by its UNECE common code, packed into `UnitId` one character a
byte (`"MTR"` -> 0x4D5452), in the namespace `http://www.opcfoundation.org/UA/units/un/cefact`. A unit the
table does not know still gets its text as DisplayName, with UnitId -1 ("no code").
"""
from __future__ import annotations

from dataclasses import dataclass

UNECE_NAMESPACE = "http://www.opcfoundation.org/UA/units/un/cefact"


@dataclass(frozen=True)
class Unit:
    code: str  # UNECE common code ("" when there is none)
    symbol: str  # DisplayName
    description: str

    @property
    def unit_id(self) -> int:
        return unece_unit_id(self.code) if self.code else -1


# unit text as the signal table writes it -> UNECE code, symbol, description
UNITS: dict[str, Unit] = {
    "m": Unit("MTR", "m", "metre"),
    "mm": Unit("MMT", "mm", "millimetre"),
    "rad": Unit("C81", "rad", "radian"),
    "deg": Unit("DD", "°", "degree [unit of angle]"),
    "N": Unit("NEW", "N", "newton"),
    "N*m": Unit("NU", "N·m", "newton metre"),
    "s": Unit("SEC", "s", "second [unit of time]"),
    "ms": Unit("C26", "ms", "millisecond"),
    "us": Unit("B98", "µs", "microsecond"),
    "%": Unit("P1", "%", "percent"),
    "steps": Unit("C62", "1", "one (a count of simulation steps)"),
    "kg": Unit("KGM", "kg", "kilogram"),
    "m/s": Unit("MTS", "m/s", "metre per second"),
    "rad/s": Unit("2A", "rad/s", "radian per second"),
}


def unece_unit_id(code: str) -> int:
    """OPC UA Part 8's UnitId of a UNECE common code: its characters, one byte each, big-endian."""
    unit_id = 0
    for ch in code:
        unit_id = (unit_id << 8) | ord(ch)
    return unit_id


def unit_of(text: str) -> Unit | None:
    """The unit of a signal's unit text (None for a dimensionless signal without unit text)."""
    if not text:
        return None
    return UNITS.get(text, Unit("", text, text))
