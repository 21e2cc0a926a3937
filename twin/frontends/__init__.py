"""Front ends: the cell served over a protocol (`modbus`, `opcua`) or a page (`view`), and `process`, the
adapter that runs a front end in a process of its own, fed the published snapshots."""
