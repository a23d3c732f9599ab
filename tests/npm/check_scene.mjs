// A scene recording (`skelgraph bag export --scene`) as Foxglove/Lichtblick's
// 3-D panel reads it:
// - the foxglove::SceneUpdate and foxglove::FrameTransform schemas in the file
//   are exactly what @foxglove/schemas' own generator writes (flattened by
//   components/scene/schemas/write_idl.cjs);
// - every SceneUpdate and FrameTransform decodes with @foxglove/omgidl-serialization
//   against that schema, and re-encodes to the same bytes;
// - every skeleton entity ("raw/sensor1/3") matches its source skeleton in the
//   same file (same log time, same stream, sensor and person): a sphere per
//   joint with confidence > 0 at the joint's position (float precision),
//   translucent where the joint is inferred, bones as a line list; per tick
//   one entity per stream, sensor and person that had a skeleton in it;
// - every entity's frame resolves through the transforms to one root, `cell`.
// Usage: node check_scene.mjs SCENE.mcap WRITE_IDL.cjs [live]   (prints a JSON summary)
// live: written by the recorder as samples arrived (receive times from several
// DDS threads, a few microseconds out of order): the entity count per tick may
// be off by 1 %.
import path from "node:path";
import { createRequire } from "node:module";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader, MessageWriter } from "@foxglove/omgidl-serialization";
import { openIndexed } from "./mcap_open.mjs";

const [file, writeIdl, mode] = process.argv.slice(2);
const fail = (msg) => {
  console.error(`FAIL: ${file}: ${msg}`);
  process.exit(1);
};
const require = createRequire(import.meta.url);
const { flattenedIdl } = require(path.resolve(writeIdl));
const modules = path.join(path.dirname(new URL(import.meta.url).pathname), "node_modules");
const { reader } = await openIndexed(file);

const codecs = new Map();
function codec(schema) {
  if (!codecs.has(schema.id)) {
    const text = new TextDecoder().decode(schema.data);
    if (schema.name.startsWith("foxglove::")) {
      const want = flattenedIdl(modules, schema.name.slice("foxglove::".length)).text;
      if (text !== want) fail(`the ${schema.name} schema is not what @foxglove/schemas generates`);
    }
    const defs = parseIDL(text);
    codecs.set(schema.id, { reader: new MessageReader(schema.name, defs), writer: new MessageWriter(schema.name, defs) });
  }
  return codecs.get(schema.id);
}

const skeletonTopics = { "skelgraph/skeleton/raw": "raw", "skelgraph/skeleton/fused": "fused", "skelgraph/skeleton/truth": "truth" };
const sources = new Map(); // "stream/sensor/person@logtime" -> skeleton
const ticks = new Set(); // "stream/sensor/person@tick": one entity each expected
const TICK = 33333333n; // SceneOptions::tick_s = 1/30 s
const entities = [];
const parents = new Map(); // child frame -> parent frame
let updates = 0, transforms = 0;
const count = {};
for await (const m of reader.readMessages({ validateCrcs: true })) {
  const ch = reader.channelsById.get(m.channelId);
  const schema = reader.schemasById.get(ch.schemaId);
  if (schema === undefined || schema.encoding !== "omgidl") continue;
  const stream = skeletonTopics[ch.topic];
  if (stream === undefined && !schema.name.startsWith("foxglove::")) continue;
  const { reader: r, writer: w } = codec(schema);
  const msg = r.readMessage(m.data);
  if (stream !== undefined && schema.name === "skelgraph::msg::Skeleton") {
    const id = `${stream}/${msg.sensor_id}/${msg.person_id}`;
    sources.set(`${id}@${m.logTime}`, msg);
    ticks.add(`${id}@${m.logTime / TICK}`);
    continue;
  }
  const again = w.writeMessage(msg);
  if (Buffer.compare(Buffer.from(again), Buffer.from(m.data)) !== 0) fail(`${ch.topic}: a message re-encodes differently`);
  if (schema.name === "foxglove::SceneUpdate") {
    updates++;
    for (const e of msg.entities) entities.push(e);
  } else if (schema.name === "foxglove::FrameTransform") {
    transforms++;
    const before = parents.get(msg.child_frame_id);
    if (before !== undefined && before !== msg.parent_frame_id) fail(`frame ${msg.child_frame_id} has two parents`);
    parents.set(msg.child_frame_id, msg.parent_frame_id);
  }
}
if (updates === 0) fail("no foxglove::SceneUpdate");
if (transforms === 0) fail("no foxglove::FrameTransform");

const root = (frame) => {
  for (let f = frame, hops = 0; ; f = parents.get(f), hops++) {
    if (f === "cell") return true;
    if (f === undefined || hops > 16) return false;
  }
};
const near = (a, b) => Math.abs(a - b) <= 1e-9 * Math.max(1, Math.abs(b));
let skeletonEntities = 0, spheres = 0, translucent = 0;
for (const e of entities) {
  if (!root(e.frame_id)) fail(`entity ${e.id}: frame ${e.frame_id} does not resolve to cell`);
  const kind = e.id.split("/")[0];
  count[kind] = (count[kind] ?? 0) + 1;
  if (!(kind in { raw: 1, fused: 1, truth: 1 })) continue;
  skeletonEntities++;
  if (e.lifetime.sec === 0 && e.lifetime.nsec === 0) fail(`entity ${e.id} has no lifetime`);
  const logTime = BigInt(e.timestamp.sec) * 1000000000n + BigInt(e.timestamp.nsec);
  const s = sources.get(`${e.id}@${logTime}`);
  if (s === undefined) fail(`entity ${e.id} at ${logTime}: no such skeleton in the file`);
  const shown = s.joints.filter((j) => j.confidence > 0);
  if (e.spheres.length !== shown.length) fail(`entity ${e.id}: ${e.spheres.length} spheres, ${shown.length} joints`);
  shown.forEach((j, k) => {
    const p = e.spheres[k].pose.position;
    if (!near(p.x, j.position.x) || !near(p.y, j.position.y) || !near(p.z, j.position.z)) {
      fail(`entity ${e.id}: sphere ${k} at ${JSON.stringify(p)}, joint at ${JSON.stringify(j.position)}`);
    }
    const alpha = e.spheres[k].color.a;
    if ((j.confidence >= 1) !== (alpha === 1)) fail(`entity ${e.id}: joint of confidence ${j.confidence} drawn with alpha ${alpha}`);
    if (alpha < 1) translucent++;
  });
  spheres += e.spheres.length;
  if (e.lines.length !== (shown.length > 1 ? 1 : 0) || (e.lines.length && e.lines[0].type !== 2)) {
    fail(`entity ${e.id}: bones not one line list`);
  }
}
const slack = mode === "live" ? Math.ceil(0.01 * ticks.size) : 0;
if (Math.abs(skeletonEntities - ticks.size) > slack) fail(`${skeletonEntities} skeleton entities, ${ticks.size} (stream, sensor, person, tick) with a skeleton`);
console.log(JSON.stringify({ file, updates, transforms, entities: entities.length, skeletonEntities, spheres, translucent,
  frames: [...parents.keys()].sort(), byKind: count }));
