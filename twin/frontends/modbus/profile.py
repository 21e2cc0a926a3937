"""A device profile on Modbus (`twin serve --profile`): the Robotiq gripper's registers at their published addresses.

The gripper itself (what the bytes mean) is `twin.devices.robotiq`; this module only serves its bytes.

The profile is served by the same Modbus/TCP server and PDU codec as the generated map
(`twin.frontends.modbus.server`), as a second device behind its own unit ids:

- **Robot output registers** (what the PLC writes; FC 16, 6 or 23 to write, FC 3 to read back): 8 holding
  registers at **0x0000** (the Modbus TCP layout of the 3-Finger manual, 2018 edition, and of Robotiq's
  ROS driver) and the same 8 again at **0x03E8** (1000, the Modbus RTU layout of the 2F-85 and 3-Finger
  manuals and the 3-Finger TCP examples of the 2014 edition).
- **Robot input registers** (the status; FC 4): 8 input registers at **0x0000** and again at **0x07D0**
  (2000). The status at 0x07D0 is also readable as holding registers (FC 3, read-only), as the 3-Finger
  manual's RTU example reads it, and as the read part of an FC 23 ("read 0x07D0, write 0x03E9").
- Register r holds bytes 2r (high byte) and 2r+1 (low byte) of the manuals' byte tables.
- Anything else is exception 02 (illegal data address); a write to the status, 02 as well.

Unit ids: a real gripper is alone on its link, and the manuals' frames use unit 9 (RTU) or 2 (TCP). So
with a profile the server answers the profile on **every unit id except the generated map's** (`--map-unit-id`,
default 247), unless `--unit-id` names one (then that one, 0 and 255). The generated map (every signal,
`sim.*`, lockstep's `sim.advance`) stays reachable on the map's unit id: PLC code written for the real
gripper talks to the profile unchanged, a test harness steps the simulation through the map's unit.
"""
from __future__ import annotations

from .pdu import SERVER_DEVICE_FAILURE, Images, PduHandler
from .register_map import HOLDING_REGISTER, INPUT_REGISTER, MAP_UNIT_ID, Entry, RegisterMap
from .server import ModbusServer

REGISTERS = 8  # 16 bytes
OUTPUT_ADDRESSES = (0x0000, 0x03E8)  # robot output (holding registers, read/write)
STATUS_ADDRESSES = (0x0000, 0x07D0)  # robot input (input registers)
STATUS_HOLDING = 0x07D0  # the robot input again as read-only holding registers (FC 3, FC 23's read)


def profile_register_map(kind: str) -> RegisterMap:
    """The profile's registers as a register map (raw 16-bit words; the gripper gives them meaning)."""
    entries = []

    def words(table, base, access, what):
        for r in range(REGISTERS):
            entries.append(Entry(f"{what}[{r}]@{base:#06x}", table, base + r, 1, "uint16", 1.0, "", 0, 0xFFFF, access,
                                 f"{kind} {what} register {r}: bytes {2 * r} (high) and {2 * r + 1} (low)"))

    for base in OUTPUT_ADDRESSES:
        words(HOLDING_REGISTER, base, "rw", "robot output")
    words(HOLDING_REGISTER, STATUS_HOLDING, "r", "robot input")
    for base in STATUS_ADDRESSES:
        words(INPUT_REGISTER, base, "r", "robot input")
    return RegisterMap(tuple(entries), kind)


class ProfileBackend:
    """The server's backend for a profile: images from the gripper's bytes, writes into its robot output."""

    live_addresses = frozenset()

    def __init__(self, gripper, bridge=None):
        self.gripper, self.bridge = gripper, bridge
        self._version = None
        self._images = Images(b"", b"", b"", b"")
        self._holding_size = STATUS_HOLDING + REGISTERS
        self._input_size = max(STATUS_ADDRESSES) + REGISTERS

    @property
    def images(self) -> Images:
        g = self.gripper
        if g.version != self._version:
            out, status = bytes(g.output), bytes(g.input)
            holding = bytearray(2 * self._holding_size)
            for base in OUTPUT_ADDRESSES:
                holding[2 * base:2 * base + 16] = out
            holding[2 * STATUS_HOLDING:2 * STATUS_HOLDING + 16] = status
            inputs = bytearray(2 * self._input_size)
            for base in STATUS_ADDRESSES:
                inputs[2 * base:2 * base + 16] = status
            self._images = Images(b"", b"", bytes(holding), bytes(inputs))
            self._version = g.version
        return self._images

    def submit(self, changes) -> int:
        if self.bridge is not None and self.bridge.fault:
            return SERVER_DEVICE_FAILURE
        for entry, value in changes:
            base = max(b for b in OUTPUT_ADDRESSES if b <= entry.address)
            self.gripper.write_output_word(entry.address - base, int(value))
        return 0

    def live_holding(self, address: int) -> int | None:
        return None


def serve_profile(server: ModbusServer, gripper, bridge, *, unit_id: int | None = None,
                  map_unit_id: int = MAP_UNIT_ID) -> PduHandler:
    """Answer `gripper`'s registers on `server`: on `unit_id` (with 0 and 255) if given, else on every unit id
    but `map_unit_id`, which keeps the generated map. The profile's PDUs are answered by the same codec, with
    the server's read-only and gap settings. Returns the profile's PDU handler."""
    main = server.pdus
    profile = PduHandler(profile_register_map(gripper.kind), ProfileBackend(gripper, bridge),
                         read_only=main.read_only, gaps_zero=main.gaps_zero, identity=main.identity)
    units = set(range(256)) if unit_id is None else {unit_id, 0, 255}
    units.discard(map_unit_id)
    server.units = {map_unit_id}
    server.route = lambda unit: profile if unit in units else None
    return profile
