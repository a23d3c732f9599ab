// Opens an MCAP file the way Lichtblick/Foxglove do and checks it against the
// values we wrote (EXPECTED.jsonl from tests/support/write_mcap_samples):
// - @mcap/core's stream reader reads every record with CRC validation;
// - its indexed reader finds every message through the summary and indexes;
// - @foxglove/omgidl-parser parses each schema, @foxglove/omgidl-serialization
//   decodes every message to the values written, and re-encodes it to the
//   very same bytes.
// Usage: node check_mcap.mjs FILE.mcap EXPECTED.jsonl   (prints a JSON summary)
import fs from "node:fs";
import { McapStreamReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader, MessageWriter } from "@foxglove/omgidl-serialization";
import { decompressHandlers, openIndexed } from "./mcap_open.mjs";

const [file, expectedPath] = process.argv.slice(2);
const fail = (msg) => {
  console.error(`FAIL: ${msg}`);
  process.exit(1);
};

const { bytes, reader } = await openIndexed(file);

// 1. Every record, in file order, CRCs checked.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(bytes);
let records = 0;
let streamMessages = 0;
for (let r; (r = stream.nextRecord()); ) {
  records++;
  if (r.type === "Message") streamMessages++;
}
if (!stream.done()) fail("the stream reader did not reach the end of the file");

// 2. Through the index (opened above).
const expected = fs.readFileSync(expectedPath, "utf8").trim().split("\n").map((l) => JSON.parse(l));
if (reader.statistics === undefined) fail("no statistics record");
if (Number(reader.statistics.messageCount) !== expected.length) {
  fail(`statistics count ${reader.statistics.messageCount} messages, ${expected.length} were written`);
}

const codecs = new Map();
const enumNames = new Map(); // value -> constant names, over every enum
function codec(schema) {
  if (!codecs.has(schema.name)) {
    const defs = parseIDL(new TextDecoder().decode(schema.data));
    for (const d of defs) {
      // Enums come out as modules of uint32 constants.
      for (const f of d.definitions ?? []) {
        if (f.isConstant && typeof f.value === "number") {
          if (!enumNames.has(f.value)) enumNames.set(f.value, []);
          enumNames.get(f.value).push(f.name);
        }
      }
    }
    codecs.set(schema.name, { reader: new MessageReader(schema.name, defs), writer: new MessageWriter(schema.name, defs) });
  }
  return codecs.get(schema.name);
}

function compare(got, want, path) {
  if (Array.isArray(want)) {
    if (got.length !== want.length) fail(`${path}: ${got.length} elements, wrote ${want.length}`);
    want.forEach((w, i) => compare(got[i], w, `${path}[${i}]`));
  } else if (want !== null && typeof want === "object") {
    for (const [k, v] of Object.entries(got)) {
      if (k in want) compare(v, want[k], `${path}.${k}`);
      else if (`${k}_count` in want) {
        if (v.length !== want[`${k}_count`]) fail(`${path}.${k}: ${v.length} elements, wrote ${want[`${k}_count`]}`);
      } else fail(`${path}.${k}: decoded, but not among the values written`);
    }
  } else if (typeof want === "string" && typeof got === "number") {
    const names = enumNames.get(got) ?? [];
    if (!names.some((n) => n === want || n.endsWith(`_${want}`))) fail(`${path}: enum ${got} (${names}) is not ${want}`);
  } else if (typeof want === "number") {
    const g = Number(got);
    const tol = Math.max(1e-6 * Math.abs(want), 1e-6); // float32 confidences; int64 beyond 2^53 in JSON
    if (!(Math.abs(g - want) <= tol)) fail(`${path}: decoded ${got}, wrote ${want}`);
  } else if (got !== want) {
    fail(`${path}: decoded ${JSON.stringify(got)}, wrote ${JSON.stringify(want)}`);
  }
}

let i = 0;
const topics = {};
for await (const m of reader.readMessages({ validateCrcs: true })) {
  const ch = reader.channelsById.get(m.channelId);
  const schema = reader.schemasById.get(ch.schemaId);
  const want = expected[i];
  if (want === undefined) fail(`more messages than were written`);
  if (ch.topic !== want.topic) fail(`message ${i}: topic ${ch.topic}, wrote ${want.topic}`);
  if (ch.messageEncoding !== "cdr" || schema.encoding !== "omgidl") fail(`${ch.topic}: encodings ${ch.messageEncoding}/${schema.encoding}`);
  if (schema.name !== want.type) fail(`${ch.topic}: schema ${schema.name}, wrote ${want.type}`);
  const { reader: r, writer: w } = codec(schema);
  const decoded = r.readMessage(m.data);
  compare(decoded, want.value, `message ${i} (${ch.topic})`);
  const again = w.writeMessage(decoded);
  if (Buffer.compare(Buffer.from(again), Buffer.from(m.data)) !== 0) {
    fail(`message ${i} (${ch.topic}): re-encoded ${again.length} bytes differ from the ${m.data.length} written`);
  }
  topics[ch.topic] = (topics[ch.topic] ?? 0) + 1;
  i++;
}
if (i !== expected.length) fail(`decoded ${i} messages, ${expected.length} were written`);
let metadata = 0;
for await (const _ of reader.readMetadata()) metadata++;
console.log(JSON.stringify({ file, records, streamMessages, messages: i, metadata, chunks: reader.chunkIndexes.length, topics }));
