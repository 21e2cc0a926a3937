// An independent OPC UA client (node-opcua) against `twin serve --lockstep --opcua`: browse, read, refused and
// accepted writes, Sim.Advance, a subscription. Usage: node check.js ENDPOINT STATION. Prints one JSON object.
"use strict";
const { OPCUAClient, MessageSecurityMode, SecurityPolicy, AttributeIds, DataType, StatusCodes, NodeClassMask,
        ClientSubscription, ClientMonitoredItem, TimestampsToReturn } = require("node-opcua-client");

async function main() {
  const [endpoint, station] = process.argv.slice(2);
  const client = OPCUAClient.create({ endpointMustExist: false, defaultTransactionTimeout: 300000, securityMode: MessageSecurityMode.None,
                                      securityPolicy: SecurityPolicy.None, connectionStrategy: { maxRetry: 2 },
                                      requestedSessionTimeout: 60000 });
  const out = {};
  await client.connect(endpoint);
  const session = await client.createSession();
  try {
    const nsArray = (await session.readNamespaceArray());
    const ns = nsArray.indexOf("urn:gripper-twin:station:" + station);
    out.ns = ns;
    const id = (name) => `ns=${ns};s=${name}`;
    const objects = await session.browse({ nodeId: "i=85", browseDirection: 0, includeSubtypes: true,
                                           nodeClassMask: 0, resultMask: 63 });
    out.folders = objects.references.map(r => r.browseName.name);
    const gripper = await session.browse({ nodeId: id("Gripper"), browseDirection: 0, includeSubtypes: true,
                                           nodeClassMask: 0, resultMask: 63 });
    out.gripper = gripper.references.map(r => r.nodeId.toString());
    const read = async (name) => (await session.read({ nodeId: id(name), attributeId: AttributeIds.Value })).value.value;
    out.before = { L2: await read("L2"), doGripped: await read("doGripped") };
    const dtype = await session.read({ nodeId: id("L2"), attributeId: AttributeIds.DataType });
    out.L2_datatype = dtype.value.value.toString();
    const write = async (name, dataType, value) =>
      (await session.write({ nodeId: id(name), attributeId: AttributeIds.Value, value: { value: { dataType, value } } })).name;
    out.refused = {
      out_of_range: await write("L2", DataType.Double, 0.9),
      wrong_type: await write("L2", DataType.String, "0.3"),
      output: await write("doGripped", DataType.Boolean, true),
    };
    // a subscription on doGripped while the fingers close
    const sub = ClientSubscription.create(session, { requestedPublishingInterval: 12, requestedMaxKeepAliveCount: 20,
                                                      requestedLifetimeCount: 600, publishingEnabled: true });
    const seen = [];
    const item = ClientMonitoredItem.create(sub, { nodeId: id("doGripped"), attributeId: AttributeIds.Value },
                                            { samplingInterval: 0, discardOldest: true, queueSize: 1 },
                                            TimestampsToReturn.Both);
    item.on("changed", (dv) => seen.push(dv.value.value));
    await new Promise((resolve) => item.once("changed", resolve));
    out.revised_sampling = item.result ? item.result.revisedSamplingInterval : null;
    out.accepted = [await write("L2", DataType.Double, 0.30), await write("L3", DataType.Double, 0.30),
                    await write("L4", DataType.Double, 0.30)];
    const result = await session.call({ objectId: id("Sim"), methodId: id("Sim.Advance"),
                                        inputArguments: [{ dataType: DataType.UInt32, value: 200 }] });
    out.advance = { status: result.statusCode.name, step: result.outputArguments.map(v => v.value) };
    out.after = { doGripped: await read("doGripped"), GrippedPart: await read("GrippedPart"),
                  L2_actual: await read("L2.actual"), step: await read("sim.step") };
    for (let i = 0; i < 50 && !seen.includes(true); i++) await new Promise(r => setTimeout(r, 50));
    out.subscription = seen;
    await sub.terminate();
  } finally {
    await session.close();
    await client.disconnect();
  }
  process.stdout.write("RESULT " + JSON.stringify(out) + "\n");
}

main().catch((err) => { process.stderr.write(String(err && err.stack || err) + "\n"); process.exit(1); });
