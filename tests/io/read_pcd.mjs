// Reads a PCD file with @loaders.gl/pcd (an independent reader, installed by tools/setup.sh into
// build-deps/npm) and prints what it found as JSON: the header's fields and point count, and
// every position (x y z ...). Used by TestPcdExport.cpp. Usage: node read_pcd.mjs FILE.pcd
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const { parse } = require("@loaders.gl/core");
const { PCDLoader } = require("@loaders.gl/pcd");

const bytes = readFileSync(process.argv[2]);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const cloud = await parse(buffer, PCDLoader, { worker: false });
process.stdout.write(
  JSON.stringify({
    fields: cloud.loaderData.fields,
    types: cloud.loaderData.type,
    sizes: cloud.loaderData.size,
    points: cloud.loaderData.points,
    data: cloud.loaderData.data,
    positions: Array.from(cloud.attributes.POSITION.value),
  }),
);
