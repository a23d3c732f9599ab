// Opens an MCAP file with @mcap/core's indexed reader, as Lichtblick/Foxglove
// do (zstd and lz4 chunks): shared by check_mcap.mjs and check_scene.mjs.
import fs from "node:fs";
import { McapIndexedReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";

await zstd.isLoaded;
await lz4.isLoaded;
export const decompressHandlers = {
  zstd: (buf, size) => zstd.decompress(buf, Number(size)),
  lz4: (buf, size) => lz4(buf, Number(size)),
};

// The file's bytes and its indexed reader.
export async function openIndexed(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  return { bytes, reader: await McapIndexedReader.Initialize({ readable, decompressHandlers }) };
}
