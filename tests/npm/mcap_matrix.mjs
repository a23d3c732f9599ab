// Writes one small MCAP file for every combination of the reference
// TypeScript writer's options (@mcap/core McapWriter: statistics, summary
// offsets, chunks, repeated schemas and channels, message, chunk, attachment
// and metadata indexes), each uncompressed, lz4 and zstd when chunked, with
// 64-byte chunks: 10 messages on one channel, a metadata record and an
// attachment. Files whose bytes repeat another's are written once.
// With a SOURCE file, its records (schemas, channels, messages, metadata,
// attachments) are copied instead, in 4 kB chunks, with every option on, every
// option off and each option alone turned off: the same content laid out as
// other writers lay it out.
// Usage: node mcap_matrix.mjs OUTDIR [SOURCE.mcap]
//        (prints a JSON list: file, options, compression, what was written)
import fs from "node:fs";
import path from "node:path";
import crypto from "node:crypto";
import { McapStreamReader, McapWriter, TempBuffer } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4js from "lz4js";

const [outdir, source] = process.argv.slice(2);
await zstd.isLoaded;
fs.mkdirSync(outdir, { recursive: true });
const flags = ["useStatistics", "useSummaryOffsets", "useChunks", "repeatSchemas", "repeatChannels",
               "useMessageIndex", "useChunkIndex", "useAttachmentIndex", "useMetadataIndex"];
const compressions = {
  none: undefined,
  lz4: (data) => ({ compression: "lz4", compressedData: Uint8Array.from(lz4js.compress(data)) }),
  zstd: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }),
};

// The source's records, for the copy mode.
function sourceRecords() {
  const decompressHandlers = {
    zstd: (buf, size) => zstd.decompress(buf, Number(size)),
    lz4: (buf, size) => Uint8Array.from(lz4js.decompress(buf, Number(size))),
  };
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(new Uint8Array(fs.readFileSync(source)));
  const records = [];
  for (let r; (r = stream.nextRecord()); ) records.push(r);
  if (!stream.done()) throw new Error(`${source}: the stream reader did not reach the end`);
  return records;
}

async function copyInto(writer, records) {
  const header = records.find((r) => r.type === "Header");
  await writer.start({ profile: header.profile, library: header.library });
  const schemas = new Map();
  const channels = new Map();
  let counts = { messages: 0, metadata: 0, attachments: 0, topics: {} };
  for (const r of records) {
    if (r.type === "Schema") {
      schemas.set(r.id, await writer.registerSchema({ name: r.name, encoding: r.encoding, data: r.data }));
    } else if (r.type === "Channel") {
      channels.set(r.id, { topic: r.topic, id: await writer.registerChannel({
        schemaId: r.schemaId === 0 ? 0 : schemas.get(r.schemaId), topic: r.topic,
        messageEncoding: r.messageEncoding, metadata: r.metadata }) });
    } else if (r.type === "Message") {
      const c = channels.get(r.channelId);
      await writer.addMessage({ ...r, channelId: c.id });
      counts.messages++;
      counts.topics[c.topic] = (counts.topics[c.topic] ?? 0) + 1;
    } else if (r.type === "Metadata") {
      await writer.addMetadata({ name: r.name, metadata: r.metadata });
      counts.metadata++;
    } else if (r.type === "Attachment") {
      await writer.addAttachment(r);
      counts.attachments++;
    }
  }
  return counts;
}

async function writeExample(writer) {
    await writer.start({ profile: "", library: "mcap_matrix.mjs" });
    const schema = await writer.registerSchema({ name: "Example", encoding: "jsonschema",
                                                 data: new TextEncoder().encode('{"type":"object"}') });
    const channel = await writer.registerChannel({ schemaId: schema, topic: "/example", messageEncoding: "json",
                                                   metadata: new Map([["origin", "mcap_matrix"]]) });
    for (let i = 0; i < 10; i++) {
      await writer.addMessage({ channelId: channel, sequence: i, logTime: BigInt(1000 + i), publishTime: BigInt(1000 + i),
                                data: new TextEncoder().encode(`{"i":${i}}`) });
    }
    await writer.addMetadata({ name: "run", metadata: new Map([["written_by", "mcap_matrix.mjs"]]) });
    await writer.addAttachment({ name: "note.txt", mediaType: "text/plain", logTime: 2000n, createTime: 2000n,
                                 data: new TextEncoder().encode("an attachment") });
    return { messages: 10, topics: { "/example": 10 }, metadata: 1, attachments: 1 };
}

const records = source ? sourceRecords() : null;
const combinations = [];
if (source) {
  combinations.push(flags.map(() => true), flags.map(() => false));
  flags.forEach((_, off) => combinations.push(flags.map((__, i) => i !== off)));
} else {
  for (let bits = 0; bits < 1 << flags.length; bits++) combinations.push(flags.map((_, i) => (bits & (1 << i)) !== 0));
}
const seen = new Set();
const files = [];
for (const [index, on] of combinations.entries()) {
  const options = Object.fromEntries(flags.map((f, i) => [f, on[i]]));
  for (const [name, compressChunk] of Object.entries(compressions)) {
    if (name !== "none" && !options.useChunks) continue;
    const buffer = new TempBuffer();
    const writer = new McapWriter({ writable: buffer, ...options, chunkSize: source ? 4096 : 64, compressChunk });
    const written = source ? await copyInto(writer, records) : await writeExample(writer);
    await writer.end();
    const bytes = buffer.get();
    const digest = crypto.createHash("sha256").update(bytes).digest("hex");
    if (seen.has(digest)) continue;
    seen.add(digest);
    const file = path.join(outdir, `matrix_${index}_${name}.mcap`);
    fs.writeFileSync(file, bytes);
    files.push({ file, options, compression: name, ...written });
  }
}
console.log(JSON.stringify(files));
