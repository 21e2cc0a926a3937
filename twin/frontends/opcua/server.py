"""An OPC UA server (asyncua) that serves a station's address space. It knows nothing of physics.

Like the Modbus server, it answers from what the cell published after the last completed step and hands
validated writes to the cell, which applies them at the start of the next step:

- `publish(values, applied, t)` (called for every step's snapshot, in the OPC UA process's loop: see
  `cell_link`) writes every value that changed into the address space, one DataValue per variable. Its
  SourceTimestamp is the step's simulated time on the server's clock: the UTC wall time when the server
  started, less the simulated time then, plus the step's simulated seconds (`start_clock`). In real time at
  speed 1 that is the step's due time on the wall clock; in lockstep, timestamps advance by exactly one step
  per step however fast the steps run. ServerTimestamp is the wall clock when the value was published. Each change is queued at once for every monitored item on that variable, so a
  subscription sees the value of every step, even one that lasts a single step.
- A client's write of a signal goes through `_write_signal`: outputs are read-only (BadNotWritable), a
  Variant of another type is BadTypeMismatch, a value outside the signal's range (or NaN, or a text that
  is none of an enumeration's choices) BadOutOfRange, a read-only user BadUserAccessDenied, a faulted
  simulation BadDeviceFailure; a refused write changes nothing. Accepted writes of one request are
  submitted to the cell together and read back at once as written; the twin applies them at the next step.
- Subscriptions: publishing intervals and sampling intervals below the step (including 0) are revised
  to the step; a monitored item's queue is revised up so that it holds every step of one publishing
  interval (a short pulse is never overwritten before it is sent).
- `Sim.Advance(steps)` (lockstep only) runs that many steps and returns the step count when they are done.

asyncua is a well-kept library, but its server revises nothing (a 0 ms publishing interval spins) and
copies and encodes every value per monitored item; the revisions, the per-step publication and the encoding
of notifications below are the few places where this module reaches into its internals, each marked.
"""
from __future__ import annotations

import asyncio
import functools
import logging
import math
import socket
from collections.abc import Awaitable, Callable, Mapping, Sequence
from datetime import datetime, timedelta, timezone

from asyncua import Server, ua
from asyncua.ua.ua_binary import nodeid_from_binary, struct_from_binary
from asyncua.crypto.permission_rules import User, UserRole

from .address_space import (ADVANCE_METHOD, BOOLEAN, DOUBLE, INT32, INT64, SIM_FOLDER, STRING, UINT32, AddressSpace,
                            Variable)
from twin.core.signal_table import SIM_ADVANCE

from .errors import AdvanceRefused
from .security import Security
from .serve import DEFAULT_PORT  # 4840, IANA's opcua-tcp (defined with the --opcua option; a light module)

VARIANT = {BOOLEAN: ua.VariantType.Boolean, DOUBLE: ua.VariantType.Double, INT32: ua.VariantType.Int32,
           UINT32: ua.VariantType.UInt32, INT64: ua.VariantType.Int64, STRING: ua.VariantType.String}
DATA_TYPE_ID = {BOOLEAN: ua.ObjectIds.Boolean, DOUBLE: ua.ObjectIds.Double, INT32: ua.ObjectIds.Int32,
                UINT32: ua.ObjectIds.UInt32, INT64: ua.ObjectIds.Int64, STRING: ua.ObjectIds.String}
INTEGER_VARIANTS = frozenset({ua.VariantType.SByte, ua.VariantType.Byte, ua.VariantType.Int16, ua.VariantType.UInt16,
                              ua.VariantType.Int32, ua.VariantType.UInt32, ua.VariantType.Int64,
                              ua.VariantType.UInt64})
LIMITS = {INT32: (-2**31, 2**31 - 1), UINT32: (0, 2**32 - 1), INT64: (-2**63, 2**63 - 1)}
MAX_ADVANCE = 2**32 - 1
QUEUE_CAP = 10_000  # the largest queue a monitored item is given
FASTEST_STEP_MS = 0.5  # wall time of a step at the fastest a cell runs (lockstep, --speed): sizes the queues

Submit = Callable[[Sequence[tuple[Variable, object]]], Awaitable[str | None]]  # -> None, or a Bad status code's name
Advance = Callable[[int], Awaitable[int]]  # lockstep: run n steps, return the step count when done
OnRequest = Callable[[str, bool], None]  # (source, clock_only): a session's request came (the comm-loss watchdog)

log = logging.getLogger("twin.frontends.opcua")


def free_port(host: str) -> int:
    """A TCP port free on `host` now (asyncua advertises its endpoint URL, so port 0 is chosen up front)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def _status(name: str) -> ua.StatusCode:
    return ua.StatusCode(getattr(ua.StatusCodes, name))


def variant_value(var: Variable, value):
    """A value as the cell publishes it (SI number, bool, enumeration text or index) -> the variable's value."""
    t = var.data_type
    if t == BOOLEAN:
        return bool(value)
    if t == DOUBLE:
        return float(value)
    if t == STRING:
        if isinstance(value, int) and not isinstance(value, bool):
            choices = var.spec.choices
            return choices[value] if 0 <= value < len(choices) else str(value)
        return "" if value is None else str(value)
    lo, hi = LIMITS[t]
    if isinstance(value, float) and math.isnan(value):
        return 0
    v = int(round(value))
    return lo if v < lo else hi if v > hi else v


class OpcUaServer:
    """Serves an `AddressSpace`; the cell calls `publish` after each step (see the module docstring)."""

    def __init__(self, space: AddressSpace, *, step_s: float, submit: Submit, advance: Advance | None = None,
                 security: Security | None = None, server_name: str | None = None,
                 on_request: OnRequest | None = None, clock_requests: bool = False):
        """`on_request(source, clock_only)` is called for every request of an activated session (source:
        "opcua HOST:PORT session N 'NAME'"); with `clock_requests` (lockstep), `clock_only` tells a request
        that only drives or reads simulated time (Sim.Advance calls, reads and writes of `sim.advance`)."""
        self.space = space
        self.on_request, self.clock_requests = on_request, clock_requests
        self.step_ms = step_s * 1000.0
        self._submit = submit
        self._advance = advance
        self.security = security or Security()
        self.server = Server(user_manager=self.security.user_manager())
        self.server_name = server_name or f"gripper-twin {space.station}"
        self.ns = 0
        self.endpoint = ""
        self.host, self.port = "", 0
        self._nodes: dict[ua.NodeId, Variable] = {}
        self._attr: dict[str, object] = {}  # signal name -> asyncua's AttributeValue of its Value attribute
        self._last: dict[str, object] = {}  # signal name -> the value last published
        self._var = {v.name: v for v in space}
        self.requests = 0  # writes and calls answered
        self.accepted = 0  # write batches accepted (handed to the cell)
        self._held: dict[str, int] = {}  # input written -> the batch that wrote it, until a step applied it
        self._epoch = datetime.now(timezone.utc)  # the wall time of simulated time 0 (`start_clock`)
        self._t = 0.0  # the simulated time last published
        self._started = False

    # -- start and stop ---------------------------------------------------------------------------------
    async def start(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> tuple[str, int]:
        """Build the address space and listen. Port 0: any free port. Returns the bound host and port."""
        srv = self.server
        await srv.init()
        if port == 0:
            port = free_port(host)
        url_host = f"[{host}]" if ":" in host else host
        self.endpoint = f"opc.tcp://{url_host}:{port}/gripper-twin/"
        srv.set_endpoint(self.endpoint)
        srv.set_server_name(self.server_name)
        await srv.set_application_uri(self.security.application_uri)
        srv.product_uri = "urn:gripper-twin"
        srv.manufacturer_name = "gripper-twin"
        await self.security.apply(srv, host)
        self.ns = await srv.register_namespace(self.space.namespace_uri)
        await self._build()
        self._hook_services()
        encode_each_value_once()
        if any(a.read_only for a in self.security.accounts):
            from asyncua.common.callback import CallbackType

            srv.subscribe_server_callback(CallbackType.PostRead, self._user_access_level)
        await srv.start()
        self._started = True
        self.host, self.port = host, port
        return host, port

    async def close(self) -> None:
        if self._started:
            self._started = False
            await self.server.stop()

    # -- the address space ----------------------------------------------------------------------------
    def node_id(self, name: str) -> ua.NodeId:
        return ua.NodeId(name, self.ns)

    async def _build(self) -> None:
        srv, ns = self.server, self.ns
        objects = srv.nodes.objects
        folders = {}
        for name in self.space.folders:
            folders[name] = await objects.add_folder(self.node_id(name), ua.QualifiedName(name, ns))
        items = []
        for var in self.space:
            items.append(self._variable_item(var, folders[var.folder].nodeid))
            items += self._property_items(var)
        results = await srv.iserver.isession.add_nodes(items)
        for item, res in zip(items, results):
            if not res.StatusCode.is_good():
                raise RuntimeError(f"OPC UA node {item.RequestedNewNodeId.to_string()}: {res.StatusCode}")
        aspace = srv.iserver.aspace  # asyncua internals: the per-step publication writes these directly
        for var in self.space:
            nid = self.node_id(var.name)
            self._nodes[nid] = var
            self._attr[var.name] = aspace[nid].attributes[ua.AttributeIds.Value]
        steps = ua.Argument(Name="steps", DataType=ua.NodeId(ua.ObjectIds.UInt32), ValueRank=ua.ValueRank.Scalar,
                            Description=ua.LocalizedText("how many simulation steps to run"))
        step = ua.Argument(Name="step", DataType=ua.NodeId(ua.ObjectIds.UInt32), ValueRank=ua.ValueRank.Scalar,
                           Description=ua.LocalizedText("sim.step when the steps are done"))
        method = await folders[SIM_FOLDER].add_method(self.node_id(ADVANCE_METHOD), ua.QualifiedName("Advance", ns),
                                                     self._call_advance, [steps], [step])
        await method.write_attribute(ua.AttributeIds.Description, ua.DataValue(ua.Variant(ua.LocalizedText(
            "lockstep: run this many steps and return when they are done (sim.step after them); "
            "real time: BadInvalidState"))))

    def _variable_item(self, var: Variable, parent: ua.NodeId) -> ua.AddNodesItem:
        item = ua.AddNodesItem()
        item.RequestedNewNodeId = self.node_id(var.name)
        item.BrowseName = ua.QualifiedName(var.name, self.ns)
        item.NodeClass = ua.NodeClass.Variable
        item.ParentNodeId = parent
        item.ReferenceTypeId = ua.NodeId(ua.ObjectIds.Organizes)
        item.TypeDefinition = ua.NodeId(ua.ObjectIds.AnalogItemType if var.numeric else ua.ObjectIds.BaseDataVariableType)
        attrs = ua.VariableAttributes()
        attrs.DisplayName = ua.LocalizedText(var.name)
        attrs.Description = ua.LocalizedText(var.description)
        attrs.DataType = ua.NodeId(DATA_TYPE_ID[var.data_type])
        attrs.Value = ua.Variant(variant_value(var, "" if var.data_type == STRING else 0), VARIANT[var.data_type])
        attrs.ValueRank = ua.ValueRank.Scalar
        attrs.ArrayDimensions = None
        access = ua.AccessLevel.CurrentRead.mask | (ua.AccessLevel.CurrentWrite.mask if var.writable else 0)
        attrs.AccessLevel = attrs.UserAccessLevel = access
        attrs.MinimumSamplingInterval = self.step_ms
        attrs.Historizing = False
        attrs.WriteMask = attrs.UserWriteMask = 0
        item.NodeAttributes = attrs
        return item

    def _property_items(self, var: Variable) -> list[ua.AddNodesItem]:
        props = []
        if var.numeric:
            props.append(("EURange", ua.ObjectIds.Range,
                          ua.Variant(ua.Range(Low=var.low, High=var.high), ua.VariantType.ExtensionObject)))
        if var.unit is not None:
            eu = ua.EUInformation(NamespaceUri="http://www.opcfoundation.org/UA/units/un/cefact",
                                  UnitId=var.unit.unit_id, DisplayName=ua.LocalizedText(var.unit.symbol),
                                  Description=ua.LocalizedText(var.unit.description))
            props.append(("EngineeringUnits", ua.ObjectIds.EUInformation,
                          ua.Variant(eu, ua.VariantType.ExtensionObject)))
        items = []
        for name, dtype, value in props:
            item = ua.AddNodesItem()
            item.RequestedNewNodeId = ua.NodeId(f"{var.name}#{name}", self.ns)
            item.BrowseName = ua.QualifiedName(name, 0)
            item.NodeClass = ua.NodeClass.Variable
            item.ParentNodeId = self.node_id(var.name)
            item.ReferenceTypeId = ua.NodeId(ua.ObjectIds.HasProperty)
            item.TypeDefinition = ua.NodeId(ua.ObjectIds.PropertyType)
            attrs = ua.VariableAttributes()
            attrs.DisplayName = ua.LocalizedText(name)
            attrs.DataType = ua.NodeId(dtype)
            attrs.Value = value
            attrs.ValueRank = ua.ValueRank.Scalar
            attrs.AccessLevel = attrs.UserAccessLevel = ua.AccessLevel.CurrentRead.mask
            item.NodeAttributes = attrs
            items.append(item)
        return items

    # -- publishing (the cell's side) -----------------------------------------------------------------
    def start_clock(self, t: float) -> None:
        """Simulated time `t` is now: SourceTimestamps are this wall time plus simulated seconds since."""
        self._epoch = datetime.now(timezone.utc) - timedelta(seconds=t)

    def publish(self, values: Mapping[str, object], applied: int | None = None, t: float | None = None) -> None:
        """After a step: put every changed value into the address space and queue it for its monitored items.

        `applied`: how many write batches this server accepted the step had applied (the adapter's count);
        an input written since keeps reading as written until a step has applied it. `t`: the step's
        simulated time (the SourceTimestamp; see the module docstring)."""
        if t is not None:
            self._t = t
        now = source = None
        last, attrs, variables, held = self._last, self._attr, self._var, self._held
        for name, raw in values.items():
            var = variables.get(name)
            if var is None:
                continue
            if held and name in held:
                if applied is not None and held[name] > applied:
                    continue
                del held[name]
            value = variant_value(var, raw)
            if name in last and last[name] == value and type(last[name]) is type(value):
                continue
            last[name] = value
            if now is None:
                now, source = datetime.now(timezone.utc), self._epoch + timedelta(seconds=self._t)
            dv = ua.DataValue(ua.Variant(value, VARIANT[var.data_type]), SourceTimestamp=source, ServerTimestamp=now)
            self._set(attrs[name], dv)

    def send_due(self) -> None:
        """asyncua internals: after a step's changes are queued, send them at once to every subscription that
        publishes at the step's rate and whose client has a Publish request waiting. Its own timer runs at
        the same period but at its own phase, so it would hold them back by up to a step (the same for the
        life of the subscription); it still sends whatever this leaves (and keep-alives)."""
        try:
            subscriptions = list(self.server.iserver.subscription_service.subscriptions.values())
            due = []
            for sub in subscriptions:
                if (sub.data.RevisedPublishingInterval <= self.step_ms and sub._publishing_enabled
                        and sub._triggered_datachanges):
                    processor = getattr(sub.pub_request_callback, "__self__", None)
                    if processor is not None and processor._publish_requests:
                        due.append(sub)
        except AttributeError:  # a version of asyncua this does not know: its timers send everything
            return
        for sub in due:
            task = asyncio.ensure_future(sub.publish_results())
            _CALLS.add(task)
            task.add_done_callback(_CALLS.discard)

    def _set(self, attval, dv: ua.DataValue) -> None:
        attval.value = dv
        for handle, callback in list(attval.datachange_callbacks.items()):
            if not _queue_change(callback, handle, dv):
                _run_now(callback(handle, dv))

    def show_written(self, var: Variable, value) -> None:
        """An accepted write reads back at once (as Modbus shows written coils and registers), and keeps
        reading so until a step has applied it."""
        value = variant_value(var, value)
        self._held[var.name] = self.accepted
        self._last[var.name] = value
        now = datetime.now(timezone.utc)
        self._set(self._attr[var.name], ua.DataValue(ua.Variant(value, VARIANT[var.data_type]),
                                                     SourceTimestamp=self._epoch + timedelta(seconds=self._t),
                                                     ServerTimestamp=now))

    # -- writes (the client's side) -------------------------------------------------------------------
    def _hook_services(self) -> None:
        """asyncua internals: our writes, and revised subscription parameters."""
        iserver = self.server.iserver
        attribute_service = iserver.attribute_service
        generic_write = attribute_service.write

        async def write(params: ua.WriteParameters, user: User = User(role=UserRole.Admin)) -> list[ua.StatusCode]:
            return await self._write(params, user, generic_write)

        attribute_service.write = write
        _hook_requests(iserver, self)
        subs = iserver.subscription_service
        create_subscription, create_items, modify_items = (subs.create_subscription, subs.create_monitored_items,
                                                           subs.modify_monitored_items)

        async def revised_create_subscription(params, *args, **kw):
            params.RequestedPublishingInterval = self._revised_interval(params.RequestedPublishingInterval)
            return await create_subscription(params, *args, **kw)

        async def revised_create_items(params):
            requested = self._revise_items(params, [i.RequestedParameters for i in params.ItemsToCreate])
            results = await create_items(params)
            return self._revised_results(results, requested)

        def revised_modify_items(params):
            requested = self._revise_items(params, [i.RequestedParameters for i in params.ItemsToModify])
            results = modify_items(params)
            return self._revised_results(results, requested)

        subs.create_subscription = revised_create_subscription
        subs.create_monitored_items = revised_create_items
        subs.modify_monitored_items = revised_modify_items

    def _revised_interval(self, requested: float) -> float:
        """Intervals below the step (0, negative, NaN) are revised to the step."""
        return requested if requested >= self.step_ms else self.step_ms

    def _revise_items(self, params, requested_parameters) -> list[float]:
        sub = self.server.iserver.subscription_service.subscriptions.get(params.SubscriptionId)
        publishing = sub.data.RevisedPublishingInterval if sub is not None else self.step_ms
        sampling = []
        for p in requested_parameters:
            interval = p.SamplingInterval
            if interval is None or not interval >= 0 and interval != -1:
                interval = 0.0
            if interval == -1:  # "the publishing interval"
                interval = publishing
            interval = self._revised_interval(interval)
            sampling.append(interval)
            # every step of one publishing interval fits the queue, with room for a late publish; steps come
            # faster than real time in lockstep or at --speed > 1, so count them at the fastest rate a cell steps
            needed = 2 * math.ceil(publishing / min(self.step_ms, FASTEST_STEP_MS)) + 2
            p.QueueSize = min(QUEUE_CAP, max(int(p.QueueSize or 0), needed))
        return sampling

    @staticmethod
    def _revised_results(results, sampling):
        for res, interval in zip(results, sampling):
            res.RevisedSamplingInterval = interval
        return results

    async def _write(self, params: ua.WriteParameters, user: User, generic_write) -> list[ua.StatusCode]:
        self.requests += 1
        items = params.NodesToWrite or []
        results: list[ua.StatusCode | None] = [None] * len(items)
        others: list[int] = []
        accepted: list[tuple[int, Variable, object]] = []
        for i, wv in enumerate(items):
            var = self._nodes.get(wv.NodeId)
            if var is None:
                others.append(i)
                continue
            status, value = self._check_write(wv, var, user)
            if status is not None:
                results[i] = _status(status)
            else:
                accepted.append((i, var, value))
        if accepted:
            refused = await self._submit([(var, value) for _, var, value in accepted])
            if not refused:
                self.accepted += 1
            for i, var, value in accepted:
                results[i] = _status(refused) if refused else ua.StatusCode()
                if not refused and var.writable:
                    self.show_written(var, value)
        if others:
            sub = ua.WriteParameters()
            sub.NodesToWrite = [items[i] for i in others]
            for i, res in zip(others, await generic_write(sub, user=user)):
                results[i] = res
        return results

    def _check_write(self, wv: ua.WriteValue, var: Variable, user: User) -> tuple[str | None, object]:
        """None and the value (as the twin takes it), or the name of the Bad status code refusing the write."""
        if wv.AttributeId != ua.AttributeIds.Value:
            return "BadNotWritable", None
        if self.security.read_only(user):
            return "BadUserAccessDenied", None
        if not var.writable:
            return "BadNotWritable", None
        if wv.IndexRange:
            return "BadWriteNotSupported", None
        variant = wv.Value.Value if wv.Value is not None else None
        if variant is None or variant.Value is None or variant.is_array or variant.Dimensions:
            return "BadTypeMismatch", None
        vt, value = variant.VariantType, variant.Value
        dtype = var.data_type
        if dtype in LIMITS:
            if vt not in INTEGER_VARIANTS:
                return "BadTypeMismatch", None
        elif vt != VARIANT[dtype]:
            return "BadTypeMismatch", None
        if dtype == DOUBLE and not math.isfinite(value):
            return "BadOutOfRange", None
        return _validate(var, value)

    # -- sessions: the watchdog, and what a user may do ----------------------------------------------
    def request_seen(self, processor, typeid: ua.NodeId, body) -> None:
        """A request came on a connection (asyncua's UaProcessor): report it when it belongs to an activated
        session. Never raises (a watchdog's trouble must not refuse a client's request)."""
        if self.on_request is None:
            return
        try:
            if typeid == _CREATE_SESSION:
                processor.gripper_twin_session_name = _session_name(body)
                return
            session = processor.session
            if session is None or not session.is_activated():
                return
            source = getattr(processor, "gripper_twin_source", None)
            if source is None or getattr(processor, "gripper_twin_session", None) is not session:
                source = self._source(processor, session)
            clock_only = self.clock_requests and self._clock_only(typeid, body)
            self.on_request(source, clock_only)
        except Exception:  # noqa: BLE001
            log.exception("OPC UA: the request hook failed")

    @staticmethod
    def _source(processor, session) -> str:
        peer = processor.name
        where = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) and len(peer) >= 2 else str(peer)
        name = getattr(processor, "gripper_twin_session_name", "")
        sid = session.session_id.Identifier
        source = f"opcua {where} session {sid}" + (f" {name!r}" if name else "")
        processor.gripper_twin_source, processor.gripper_twin_session = source, session
        return source

    def _clock_only(self, typeid: ua.NodeId, body) -> bool:
        """The request only drives or reads simulated time: Sim.Advance calls, reads or writes of sim.advance
        (a lockstep harness's clock, as `twin.frontends.modbus.pdu.PduHandler.clock_only`; see `twin.runtime.watchdog`)."""
        if typeid not in (_CALL_REQUEST, _READ_REQUEST, _WRITE_REQUEST):
            return False
        b = _parameters(body)
        if typeid == _CALL_REQUEST:
            advance = self.node_id(ADVANCE_METHOD)
            calls = struct_from_binary(ua.CallParameters, b).MethodsToCall or []
            return bool(calls) and all(c.MethodId == advance for c in calls)
        clock = self.node_id(SIM_ADVANCE)
        if typeid == _READ_REQUEST:
            items = struct_from_binary(ua.ReadParameters, b).NodesToRead or []
        else:
            items = struct_from_binary(ua.WriteParameters, b).NodesToWrite or []
        return bool(items) and all(i.NodeId == clock for i in items)

    def _user_access_level(self, event, _dispatcher) -> None:
        """asyncua's PostRead callback: a read-only user's session reads the UserAccessLevel of an input as
        CurrentRead only (the node's own attribute, the same for every session, says CurrentWrite)."""
        if not self.security.read_only(event.user):
            return
        results = event.response_params
        for i, rv in enumerate(event.request_params.NodesToRead or []):
            if rv.AttributeId == ua.AttributeIds.UserAccessLevel and rv.NodeId in self._nodes:
                dv = results[i]
                if dv.Value is not None and dv.Value.Value is not None:
                    level = int(dv.Value.Value) & ~ua.AccessLevel.CurrentWrite.mask
                    results[i] = ua.DataValue(ua.Variant(level, ua.VariantType.Byte), StatusCode=dv.StatusCode)

    # -- Sim.Advance -----------------------------------------------------------------------------------
    async def _call_advance(self, parent: ua.NodeId, *args) -> ua.CallMethodResult | list[ua.Variant]:
        self.requests += 1
        result = ua.CallMethodResult()
        if len(args) != 1:
            result.StatusCode = _status("BadArgumentsMissing" if not args else "BadTooManyArguments")
            return result
        arg = args[0]
        if not isinstance(arg, ua.Variant) or arg.VariantType not in INTEGER_VARIANTS or arg.is_array:
            result.StatusCode = _status("BadInvalidArgument")
            result.InputArgumentResults = [_status("BadTypeMismatch")]
            return result
        n = int(arg.Value)
        if not 0 <= n <= MAX_ADVANCE:
            result.StatusCode = _status("BadInvalidArgument")
            result.InputArgumentResults = [_status("BadOutOfRange")]
            return result
        if self._advance is None:
            result.StatusCode = _status("BadInvalidState")
            return result
        try:
            step = await self._advance(n)
        except AdvanceRefused as exc:
            result.StatusCode = _status(exc.status)
            return result
        result.InputArgumentResults = [ua.StatusCode()]
        result.OutputArguments = [ua.Variant(min(int(step), MAX_ADVANCE), ua.VariantType.UInt32)]
        return result


def _validate(var: Variable, value) -> tuple[str | None, object]:
    """The signal table's own check of a written value, as Modbus applies it: range (and choices)."""
    spec = var.spec
    check = getattr(spec, "check", None)
    if check is not None:
        from twin.core.errors import TwinError

        from .errors import status_of

        try:
            return None, check(value)
        except TwinError as exc:  # by the error's type, as the exchange's refusals are
            return status_of(exc), None
    if var.data_type == STRING:
        return (None, value) if value in spec.choices else ("BadOutOfRange", None)
    if var.data_type in LIMITS:
        lo, hi = LIMITS[var.data_type]
        if not lo <= value <= hi:
            return "BadOutOfRange", None
    if var.numeric:
        if spec.min is not None and value < spec.min or spec.max is not None and value > spec.max:
            return "BadOutOfRange", None
    return None, value


_CALL_REQUEST = ua.NodeId(ua.ObjectIds.CallRequest_Encoding_DefaultBinary)
_READ_REQUEST = ua.NodeId(ua.ObjectIds.ReadRequest_Encoding_DefaultBinary)
_WRITE_REQUEST = ua.NodeId(ua.ObjectIds.WriteRequest_Encoding_DefaultBinary)
_CREATE_SESSION = ua.NodeId(ua.ObjectIds.CreateSessionRequest_Encoding_DefaultBinary)


def _hook_requests(iserver, server: "OpcUaServer") -> None:
    """asyncua internals, at the door of every request of a connection (`UaProcessor.process_message`):

    - every request of an activated session is reported to `server.request_seen` (the comm-loss watchdog);
    - a connection's requests are processed one after another, so a Sim.Advance of a few seconds would hold
      up that client's every other request (asyncua's client then drops the connection when its watchdog
      read goes unanswered). Method calls to this server run as tasks of their own instead, and are answered
      when done; the connection reads on. OPC UA matches responses by request handle.

    The patch is on the class, but acts only for the servers that set `iserver.gripper_twin`."""
    from asyncua.server.uaprocessor import UaProcessor

    iserver.gripper_twin = server
    if getattr(UaProcessor, "_gripper_twin_patched", False):
        return
    process_message = UaProcessor.process_message

    async def hooked(self, seqhdr, body):
        server = getattr(self.iserver, "gripper_twin", None)
        if server is not None:
            typeid = nodeid_from_binary(body.copy())
            server.request_seen(self, typeid, body)
            if typeid == _CALL_REQUEST:
                task = asyncio.ensure_future(process_message(self, seqhdr, body))
                _CALLS.add(task)
                task.add_done_callback(_CALLS.discard)
                return True
        return await process_message(self, seqhdr, body)

    UaProcessor.process_message = hooked
    UaProcessor._gripper_twin_patched = True


_CALLS: set = set()  # running method calls and sends (a task needs a reference until it is done)


def _parameters(body):
    """A copy of a request's body, past its type id and request header: at its parameters."""
    b = body.copy()
    nodeid_from_binary(b)
    struct_from_binary(ua.RequestHeader, b)
    return b


def _session_name(body) -> str:
    """The SessionName a CreateSession request carries (the client's name for its session)."""
    return struct_from_binary(ua.CreateSessionParameters, _parameters(body)).SessionName or ""


_NO_DEADBAND = (None, ua.DeadbandType.None_)


def _queue_change(callback, handle: int, dv: ua.DataValue) -> bool:
    """asyncua internals, the hot path: queue a changed value for one monitored item of a subscription, as its
    datachange callback would, without deep-copying the DataValue per item (publish never changes a DataValue
    it has handed out: it makes a new one per change). False: leave it to asyncua's own callback (an item with
    a deadband filter, or a version of asyncua this does not know)."""
    service = getattr(callback, "__self__", None)
    try:
        mid = service._monitored_datachange[handle]
        mdata = service._monitored_items[mid]
        queues = service.isub._triggered_datachanges
    except (AttributeError, KeyError):
        return False
    flt = mdata.filter
    if flt is not None and getattr(flt, "DeadbandType", None) not in _NO_DEADBAND:
        return False
    if mdata.mode == ua.MonitoringMode.Disabled:
        return True
    values = mdata.mvalue
    values.old_dvalue, values.current_dvalue = values.current_dvalue, dv
    notification = ua.MonitoredItemNotification(ClientHandle=mdata.client_handle, Value=dv)
    queue = queues.get(mid)
    if queue is None:
        queues[mid] = [notification]
    else:
        if mdata.queue_size and len(queue) >= mdata.queue_size:
            del queue[0]
        queue.append(notification)
    return True


def encode_each_value_once() -> None:
    """asyncua internals, the other hot path: a publish response carries one MonitoredItemNotification per
    monitored item and change, and asyncua's generic encoder encodes each one's DataValue anew (about 12 us
    each: 4 ms a step for 1000 items on the ring rig). `publish` hands one DataValue to every item of a
    variable, so here each DataValue is encoded once and its bytes reused: the same bytes, a sixth of the
    time. Installed for the process (asyncua's encoders are module-level); a notification whose DataValue
    changed since it was encoded is encoded anew."""
    from asyncua.ua import ua_binary

    if getattr(ua_binary, "_gripper_twin_each_value_once", False):
        return
    original = ua_binary.create_type_serializer
    generic = original(ua.MonitoredItemNotification)
    encode_value = ua_binary.create_dataclass_serializer(ua.DataValue)
    pack_handle = ua_binary.Primitives.UInt32.pack
    encoded: dict[int, tuple] = {}  # id(DataValue) -> (it, its fields, its bytes)

    def notification(n) -> bytes:
        dv = n.Value
        if dv is None or n.ClientHandle is None:
            return generic(n)
        hit = encoded.get(id(dv))
        if (hit is None or hit[0] is not dv or hit[1] is not dv.Value or hit[2] is not dv.StatusCode
                or hit[3] is not dv.SourceTimestamp or hit[4] is not dv.ServerTimestamp):
            if len(encoded) >= 4096:
                encoded.clear()
            hit = (dv, dv.Value, dv.StatusCode, dv.SourceTimestamp, dv.ServerTimestamp, encode_value(dv))
            encoded[id(dv)] = hit
        return pack_handle(n.ClientHandle) + hit[5]

    @functools.cache
    def create_type_serializer(uatype):
        return notification if uatype is ua.MonitoredItemNotification else original(uatype)

    ua_binary.create_type_serializer = create_type_serializer
    ua_binary._gripper_twin_each_value_once = True


def _run_now(coro) -> None:
    """Run one of asyncua's datachange callbacks to its end now. They never wait (a monitored item's queue is
    a list, and publishing intervals are never 0 here), so the step's publication stays in the step."""
    try:
        coro.send(None)
    except StopIteration:
        return
    coro.close()
    log.error("an asyncua datachange callback waited: its notification was dropped")
