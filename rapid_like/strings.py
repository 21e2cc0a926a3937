"""RAPID's string and byte functions as pure Python: StrFind, StrMatch, StrMemb, StrOrder, StrMap,
StrToByte, ByteToStr, DecToHex, HexToDec, and the packing of numbers into rawbytes
(PackRawBytes/UnpackRawBytes). Positions are 1-based, as in RAPID; a search that finds nothing
returns the string's length + 1, as the manual says.
"""
from __future__ import annotations

import struct

RAWBYTES_MAX = 1024  # bytes in a rawbytes


def str_find(s: str, pos: int, charset: str, not_in_set: bool = False) -> int:
    for i in range(max(pos, 1) - 1, len(s)):
        if (s[i] in charset) != not_in_set:
            return i + 1
    return len(s) + 1


def str_match(s: str, pos: int, pattern: str) -> int:
    i = s.find(pattern, max(pos, 1) - 1)
    return i + 1 if i >= 0 else len(s) + 1


def str_order(a: str, b: str, order: str) -> bool:
    """Is `a` before or equal to `b` in the character order `order` (characters not in it come after,
    by their code)?"""
    def key(c: str) -> tuple[int, int]:
        i = order.find(c)
        return (0, i) if i >= 0 else (1, ord(c))
    return [key(c) for c in a] <= [key(c) for c in b]


def str_map(s: str, from_map: str, to_map: str) -> str:
    table = {f: t for f, t in zip(from_map, to_map)}
    return "".join(table.get(c, c) for c in s)


def str_to_byte(text: str, fmt: str) -> int:
    base = {"hex": 16, "okt": 8, "bin": 2}.get(fmt)
    if fmt == "char":
        if len(text) != 1:
            raise ValueError(f"StrToByte \\Char takes one character, not {text!r}")
        value = ord(text)
    else:
        value = int(text, base or 10)
    if not 0 <= value <= 255:
        raise ValueError(f"{text!r} is not a byte (0 to 255)")
    return value


def byte_to_str(value: int, fmt: str) -> str:
    if fmt == "hex":
        return f"{value:02X}"
    if fmt == "okt":
        return f"{value:03o}"
    if fmt == "bin":
        return f"{value:08b}"
    if fmt == "char":
        return chr(value)
    return str(value)


_INT_FORMATS = {1: "B", 2: "H", 4: "I", 8: "Q", -1: "b", -2: "h", -4: "i", -8: "q"}


def pack(value: object, intx: int | None, float4: bool, hex1: bool, network: bool) -> bytes:
    """The bytes PackRawBytes writes for `value`: \\IntX (1, 2, 4, 8 bytes; negative sizes signed),
    \\Float4, \\Hex1 (one byte) or, for a string, its characters (\\ASCII)."""
    order = ">" if network else "<"
    if isinstance(value, str):
        return value.encode("latin-1")
    if isinstance(value, bool):
        value = float(value)
    if hex1:
        return bytes([int(value) & 0xFF])  # type: ignore[call-overload]
    if float4:
        return struct.pack(order + "f", float(value))  # type: ignore[arg-type]
    if intx is None or intx not in _INT_FORMATS:
        raise ValueError("PackRawBytes of a num needs \\IntX (USINT, UINT, UDINT, ULINT, SINT, INT, DINT, LINT), "
                         "\\Float4 or \\Hex1")
    return struct.pack(order + _INT_FORMATS[intx], int(value))  # type: ignore[call-overload]


def unpack(data: bytes, start: int, intx: int | None, float4: bool, ascii_len: int | None, hex1: bool,
           network: bool) -> object:
    order = ">" if network else "<"
    i = start - 1
    if ascii_len is not None:
        chunk = data[i:i + ascii_len]
        if len(chunk) < ascii_len:
            raise IndexError
        return chunk.decode("latin-1")
    if hex1:
        if i >= len(data):
            raise IndexError
        return float(data[i])
    fmt = "f" if float4 else _INT_FORMATS.get(intx or 0)
    if fmt is None:
        raise ValueError("UnpackRawBytes needs \\IntX, \\Float4, \\ASCII or \\Hex1")
    size = struct.calcsize(fmt)
    if i < 0 or i + size > len(data):
        raise IndexError
    return float(struct.unpack(order + fmt, bytes(data[i:i + size]))[0])
