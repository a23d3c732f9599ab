// Writes the OMG IDL of Foxglove message schemas as scene recordings carry it:
//   node write_idl.cjs NODE_MODULES OUT_DIR NAME...   (NAME: SceneUpdate, FrameTransform, ...)
// Each OUT_DIR/foxglove.NAME.idl is what @foxglove/schemas' own generator
// (generateOmgIdl) writes for NAME and every schema it includes, flattened
// mechanically for MCAP's `omgidl` encoding (one text, no #include): the
// included schemas first, each once, in the order a depth-first walk of the
// #include lines meets them, with the #include lines dropped. Nothing is typed
// by hand. Also a module: flattenedIdl(NODE_MODULES, NAME) gives the text
// (the npm test compares it with what a scene recording carries).
"use strict";
const fs = require("fs");
const path = require("path");

const include = /^#include "foxglove\/(\w+)\.idl"\s*$/;
function flatten(texts, name, seen, parts) {
  if (seen.has(name)) return;
  seen.add(name);
  const text = texts.get(name);
  if (text === undefined) throw new Error(`no Foxglove schema ${name}`);
  const body = [];
  for (const line of text.split("\n")) {
    const m = include.exec(line);
    if (m) flatten(texts, m[1], seen, parts);
    else if (!line.startsWith("#")) body.push(line);
  }
  parts.push(body.join("\n").trim() + "\n");
}

// The flattened IDL of foxglove::NAME and how many schemas it includes.
function flattenedIdl(modules, name) {
  const pkg = (p) => require(path.join(path.resolve(modules), "@foxglove/schemas", p));
  const { foxgloveMessageSchemas, foxgloveEnumSchemas } = pkg("internal");
  const { generateOmgIdl, omgIdlMessageSchemaName } = pkg("dist/internal/generateOmgIdl.js");
  const texts = new Map();  // IDL name -> generated text
  for (const s of Object.values(foxgloveMessageSchemas)) texts.set(omgIdlMessageSchemaName(s), generateOmgIdl(s));
  for (const s of Object.values(foxgloveEnumSchemas)) texts.set(s.name, generateOmgIdl(s));
  const parts = [];
  flatten(texts, name, new Set(), parts);
  return { text: parts.join("\n"), included: parts.length - 1 };
}
module.exports = { flattenedIdl };

if (require.main === module) {
  const [modules, out, ...names] = process.argv.slice(2);
  if (!modules || !out || names.length === 0) {
    console.error("usage: node write_idl.cjs NODE_MODULES OUT_DIR NAME...");
    process.exit(2);
  }
  fs.mkdirSync(out, { recursive: true });
  for (const name of names) {
    const { text, included } = flattenedIdl(modules, name);
    const file = path.join(out, `foxglove.${name}.idl`);
    fs.writeFileSync(file, text);
    console.log(`${file}: foxglove::${name} and ${included} schemas it uses`);
  }
}
