"""The numbers of Modbus/TCP, defined once, in a module that imports nothing.

The server's request handling (`pdu`, `server`), the `twin serve` parser (`cli`, which must not pay for
asyncio or the register map when it only builds its parser) and the PLC client (`plc_client`) all take
them from here. Limits and exception codes: the MODBUS Application Protocol Specification V1.1b3
(sections 6 and 7); ports: IANA's registry (502 mbap, 802 mbap-s) and this project's defaults.
"""

# -- per request (the PDU is at most 253 bytes) ------------------------------------------------------------
MAX_PDU = 253
MAX_READ_BITS, MAX_READ_REGISTERS = 2000, 125  # functions 1, 2 / 3, 4
MAX_WRITE_BITS, MAX_WRITE_REGISTERS = 1968, 123  # functions 15 / 16
MAX_RW_READ, MAX_RW_WRITE = 125, 121  # function 23: its read part, its write part

ADDRESSES = 0x10000  # addresses per table (16-bit, 0..65535)

# -- exception codes ----------------------------------------------------------------------------------------
ILLEGAL_FUNCTION, ILLEGAL_DATA_ADDRESS, ILLEGAL_DATA_VALUE, SERVER_DEVICE_FAILURE = 0x01, 0x02, 0x03, 0x04
GATEWAY_TARGET_FAILED = 0x0B
EXCEPTION_NAMES = {1: "illegal function", 2: "illegal data address", 3: "illegal data value",
                   4: "server device failure", 5: "acknowledge", 6: "server device busy",
                   8: "memory parity error", 10: "gateway path unavailable", 11: "gateway target failed to respond"}

# -- ports ------------------------------------------------------------------------------------------------------
TLS_PORT = 802  # Modbus/TCP Security (mbap/TLS), IANA's registered port
DEFAULT_PORT = 5020  # `twin serve`'s plain Modbus/TCP port, and the client's default (502 needs root)

# -- the twin's server: its defaults (`twin serve --max-connections`, `--requests-per-step`) -----------------
MAX_CONNECTIONS = 64
REQUESTS_PER_STEP = 400  # global budget: requests answered per step period, over all connections
