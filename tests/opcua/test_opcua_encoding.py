"""The server encodes a publish response's notifications with each DataValue encoded once: the bytes must be
exactly those of asyncua's own encoder, and decode back to the same values."""
from __future__ import annotations

from datetime import datetime, timezone

from asyncua import ua
from asyncua.ua import ua_binary

from twin.frontends.opcua.server import encode_each_value_once


def test_notifications_encode_to_the_same_bytes_as_asyncuas_own_encoder():
    generic = ua_binary.create_dataclass_serializer(ua.MonitoredItemNotification)  # asyncua's, per item
    now = datetime(2026, 11, 23, 21, 0, 0, 123456, tzinfo=timezone.utc)
    values = [ua.DataValue(ua.Variant(0.32, ua.VariantType.Double), SourceTimestamp=now, ServerTimestamp=now),
              ua.DataValue(ua.Variant(True, ua.VariantType.Boolean), SourceTimestamp=now, ServerTimestamp=now),
              ua.DataValue(ua.Variant("ring", ua.VariantType.String), SourceTimestamp=now),
              ua.DataValue(ua.Variant(4_000_000_000, ua.VariantType.UInt32)),
              ua.DataValue(StatusCode=ua.StatusCode(ua.StatusCodes.BadOutOfRange))]
    items = [ua.MonitoredItemNotification(ClientHandle=h, Value=values[h % len(values)]) for h in range(40)]
    expected = b"".join(generic(n) for n in items)
    encode_each_value_once()
    notification = ua.DataChangeNotification(MonitoredItems=items)
    data = ua_binary.struct_to_binary(notification)
    assert data[:4] == (40).to_bytes(4, "little") and data[4:4 + len(expected)] == expected  # count, then the items
    assert ua_binary.struct_to_binary(notification) == data  # encoded again from the kept bytes
    changed = ua.DataValue(ua.Variant(0.33, ua.VariantType.Double), SourceTimestamp=now, ServerTimestamp=now)
    items[0].Value = changed  # a new value for one item: its own bytes
    again = ua_binary.struct_to_binary(notification)
    decoded = ua_binary.struct_from_binary(ua.DataChangeNotification, ua.utils.Buffer(again))
    assert [n.ClientHandle for n in decoded.MonitoredItems] == list(range(40))
    assert decoded.MonitoredItems[0].Value.Value.Value == 0.33
    assert [n.Value.Value for n in decoded.MonitoredItems[1:]] == [n.Value.Value for n in items[1:]]
    assert decoded.MonitoredItems[4].Value.StatusCode == ua.StatusCode(ua.StatusCodes.BadOutOfRange)
