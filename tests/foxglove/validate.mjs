// Validates what `sweeptrace replay --foxglove` writes against Foxglove's
// published JSON Schemas (the npm package @foxglove/schemas, pinned in
// package-lock.json).
//
//   node validate.mjs DUMP.jsonl...        # dumps of scripts/foxglove_dump.py --dump
//   node validate.mjs --check-copies DIR   # DIR/SceneUpdate.json, DIR/Log.json equal the package's
//
// For each dump: every schema record named foxglove.X must equal the
// package's schema X; every message is validated against the package's
// schema for its schema name (foxglove.*), or against the schema embedded
// in the file (the project's own, sweeptrace.*), and also against a closed
// variant (no property beyond those the schema lists), so a misspelled
// field is caught too. Exits 1 on any failure.

import { readFileSync } from "node:fs";
import { isDeepStrictEqual } from "node:util";
import { createRequire } from "node:module";
import Ajv from "ajv";
import Ajv2020 from "ajv/dist/2020.js";

const require = createRequire(import.meta.url);
const published = require("@foxglove/schemas/jsonschema");

const MAX_REPORTED = 10;
let failures = 0;
function fail(message) {
  failures += 1;
  if (failures <= MAX_REPORTED) console.error(`FAIL ${message}`);
}

/** A copy of `schema` where every object schema with `properties` admits no other property. */
function closed(schema) {
  if (Array.isArray(schema)) return schema.map(closed);
  if (schema === null || typeof schema !== "object") return schema;
  const out = {};
  for (const [key, value] of Object.entries(schema)) {
    out[key] = key === "properties"
      ? Object.fromEntries(Object.entries(value).map(([k, v]) => [k, closed(v)]))
      : closed(value);
  }
  if (out.properties && out.additionalProperties === undefined) out.additionalProperties = false;
  return out;
}

function compiler(schema) {
  const draft2020 = typeof schema.$schema === "string" && schema.$schema.includes("2020-12");
  const ajv = draft2020 ? new Ajv2020({ allErrors: true, strict: true }) : new Ajv({ allErrors: true, strict: true });
  const { $id, ...rest } = schema; // compiled twice (open and closed): no id clash
  return [ajv.compile(rest), ajv.compile(closed(rest))];
}

function packageSchema(name) {
  const short = name.replace(/^foxglove\./, "");
  return name.startsWith("foxglove.") ? published[short] : undefined;
}

function checkCopies(dir) {
  for (const name of ["SceneUpdate", "Log"]) {
    const copy = JSON.parse(readFileSync(`${dir}/${name}.json`, "utf8"));
    if (!isDeepStrictEqual(copy, published[name])) {
      fail(`${dir}/${name}.json differs from @foxglove/schemas' ${name}: regenerate it from the package`);
    } else {
      console.log(`ok   ${dir}/${name}.json equals @foxglove/schemas' ${name}`);
    }
  }
}

function validateDump(path) {
  const validators = new Map();
  const counts = new Map();
  const lines = readFileSync(path, "utf8").split("\n").filter((l) => l.length > 0);
  for (const [i, line] of lines.entries()) {
    const record = JSON.parse(line);
    if (record.topic === undefined) {
      // A schema record.
      const own = packageSchema(record.schema);
      if (record.schema.startsWith("foxglove.")) {
        if (own === undefined) {
          fail(`${path}: schema ${record.schema} is not in @foxglove/schemas`);
          continue;
        }
        if (!isDeepStrictEqual(record.data, own)) {
          fail(`${path}: the embedded schema ${record.schema} differs from @foxglove/schemas'`);
        }
        validators.set(record.schema, compiler(own));
      } else {
        validators.set(record.schema, compiler(record.data));
      }
      continue;
    }
    const pair = validators.get(record.schema);
    if (pair === undefined) {
      fail(`${path}:${i + 1}: ${record.topic}: no schema record for ${record.schema}`);
      continue;
    }
    for (const [variant, validate] of [["published", pair[0]], ["closed", pair[1]]]) {
      if (!validate(record.data)) {
        fail(`${path}:${i + 1}: ${record.topic} (${record.schema}, log_time ${record.log_time}) against the ${variant} schema: ${JSON.stringify(validate.errors.slice(0, 3))}`);
      }
    }
    counts.set(record.topic, (counts.get(record.topic) || 0) + 1);
  }
  const total = [...counts.values()].reduce((a, b) => a + b, 0);
  if (total === 0) fail(`${path}: no messages`);
  const summary = [...counts.entries()].sort().map(([t, n]) => `${t} ${n}`).join(", ");
  console.log(`${failures === 0 ? "ok  " : "done"} ${path}: ${total} messages validated (${summary})`);
}

const args = process.argv.slice(2);
if (args.length === 0) {
  console.error("usage: node validate.mjs DUMP.jsonl... | --check-copies DIR");
  process.exit(2);
}
for (let i = 0; i < args.length; i++) {
  if (args[i] === "--check-copies") checkCopies(args[++i]);
  else validateDump(args[i]);
}
if (failures > 0) {
  console.error(`${failures} failure(s)${failures > MAX_REPORTED ? ` (first ${MAX_REPORTED} shown)` : ""}`);
  process.exit(1);
}
