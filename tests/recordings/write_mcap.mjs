// Writes an MCAP file (ROS 2: CDR messages, ros2msg schemas) from a KITTI-layout folder with the
// npm packages @mcap/core and @foxglove/rosmsg2-serialization: an independent writer of the
// recordings strata's tests read (tests/recordings/). Nothing of strata is used. tools/setup.sh
// installs the packages into build-deps/npm (NODE_PATH points there).
//
//   node write_mcap.mjs SEQ OUT.mcap [--compression none|lz4|zstd] [--chunk-kb N]
//                       [--point-time t] [--tf-rate K] [--no-summary] [--dump DIR]
//
// --dump DIR also writes every message's CDR bytes to DIR (NNNNNN.cdr, and messages.jsonl with
// each one's topic, type and time) for write_db3.py, which makes a rosbag2 SQLite bag of them.
//
// As write_ros1_bag.py: each scan a sensor_msgs/msg/PointCloud2 on /velodyne_points in frame
// "velodyne" (intensity first, a pad byte, then x y z float32), stamped 0.1 s apart; /tf carries
// world -> base_link (K poses per scan interval), /tf_static base_link -> velodyne. Chunks are
// compressed by the lz4 and zstd programs (Debian's lz4 and zstd packages).
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const { McapWriter } = require("@mcap/core");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const { parse } = require("@foxglove/rosmsg");

const T0 = 1317029540n * 1000000000n;
const MOUNT_YAW = (2.0 * Math.PI) / 180.0;
const MOUNT = [
  [Math.cos(MOUNT_YAW), -Math.sin(MOUNT_YAW), 0, 1.2],
  [Math.sin(MOUNT_YAW), Math.cos(MOUNT_YAW), 0, 0],
  [0, 0, 1, 1.73],
  [0, 0, 0, 1],
];

const SEP = "\n================================================================================\n";
const HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id";
const TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec";
const CLOUD =
  "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n" +
  "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense" +
  SEP + HEADER + SEP + TIME + SEP +
  "MSG: sensor_msgs/PointField\nstring name\nuint32 offset\nuint8 datatype\nuint32 count";
const TF =
  "geometry_msgs/TransformStamped[] transforms" + SEP +
  "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n" +
  "geometry_msgs/Transform transform" + SEP + HEADER + SEP + TIME + SEP +
  "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation" +
  SEP + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z" + SEP +
  "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w";

function args() {
  const a = process.argv.slice(2);
  const o = { seq: a[0], out: a[1], compression: "none", chunkKb: 768, pointTime: "none", tfRate: 1, summary: true };
  for (let i = 2; i < a.length; ++i) {
    if (a[i] === "--compression") o.compression = a[++i];
    else if (a[i] === "--chunk-kb") o.chunkKb = Number(a[++i]);
    else if (a[i] === "--point-time") o.pointTime = a[++i];
    else if (a[i] === "--tf-rate") o.tfRate = Number(a[++i]);
    else if (a[i] === "--no-summary") o.summary = false;
    else if (a[i] === "--dump") o.dump = a[++i];
    else throw new Error(`unknown option ${a[i]}`);
  }
  return o;
}

const matmul = (a, b) => a.map((r) => b[0].map((_, j) => r.reduce((s, v, k) => s + v * b[k][j], 0)));
function rigidInverse(m) {
  const r = [0, 1, 2].map((i) => [0, 1, 2].map((j) => m[j][i]));
  const t = [0, 1, 2].map((i) => -(r[i][0] * m[0][3] + r[i][1] * m[1][3] + r[i][2] * m[2][3]));
  return [[...r[0], t[0]], [...r[1], t[1]], [...r[2], t[2]], [0, 0, 0, 1]];
}
function readMatrix(line) {
  const v = line.trim().split(/\s+/).slice(-12).map(Number);
  return [v.slice(0, 4), v.slice(4, 8), v.slice(8, 12), [0, 0, 0, 1]];
}
function quaternion(m) {
  const t = m[0][0] + m[1][1] + m[2][2];
  if (t > 0) {
    const s = Math.sqrt(t + 1) * 2;
    return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s];
  }
  const i = [0, 1, 2].reduce((b, k) => (m[k][k] > m[b][b] ? k : b), 0);
  const j = (i + 1) % 3, k = (i + 2) % 3;
  const s = Math.sqrt(1 + m[i][i] - m[j][j] - m[k][k]) * 2;
  const q = [0, 0, 0, 0];
  q[i] = 0.25 * s;
  q[j] = (m[j][i] + m[i][j]) / s;
  q[k] = (m[k][i] + m[i][k]) / s;
  q[3] = (m[k][j] - m[j][k]) / s;
  return q;
}
function slerp(q0, q1, a) {
  let d = q0.reduce((s, v, i) => s + v * q1[i], 0);
  if (d < 0) { q1 = q1.map((v) => -v); d = -d; }
  if (d > 0.9995) {
    const q = q0.map((v, i) => v + a * (q1[i] - v));
    const n = Math.hypot(...q);
    return q.map((v) => v / n);
  }
  const th = Math.acos(d);
  return q0.map((v, i) => (Math.sin((1 - a) * th) * v + Math.sin(a * th) * q1[i]) / Math.sin(th));
}
const stampOf = (ns) => ({ sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) });
const transform = (parent, child, ns, q, p) => ({
  header: { stamp: stampOf(ns), frame_id: parent },
  child_frame_id: child,
  transform: { translation: { x: p[0], y: p[1], z: p[2] }, rotation: { x: q[0], y: q[1], z: q[2], w: q[3] } },
});

function compressor(kind) {
  if (kind === "none") return undefined;
  return (data) => ({
    compression: kind,
    compressedData: new Uint8Array(execFileSync(kind, ["-c", "-q"], { input: Buffer.from(data), maxBuffer: 1 << 30 })),
  });
}

async function main() {
  const o = args();
  let tr = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]];
  const calib = path.join(o.seq, "calib.txt");
  if (fs.existsSync(calib)) {
    const line = fs.readFileSync(calib, "utf8").split("\n").find((l) => l.startsWith("Tr:"));
    if (line) tr = readMatrix(line);
  }
  const cams = fs.readFileSync(path.join(o.seq, "poses.txt"), "utf8").split("\n").filter((l) => l.trim()).map(readMatrix);
  const bins = fs.readdirSync(path.join(o.seq, "velodyne")).filter((f) => f.endsWith(".bin")).sort();
  const base = bins.map((_, i) => matmul(matmul(matmul(rigidInverse(tr), cams[i]), tr), rigidInverse(MOUNT)));
  const stamps = bins.map((_, k) => T0 + BigInt(k) * 100000000n);

  const chunks = [];
  let position = 0n;
  const writable = { position: () => position, write: async (b) => { chunks.push(Buffer.from(b)); position += BigInt(b.byteLength); } };
  const writer = new McapWriter({
    writable, chunkSize: o.chunkKb * 1024, compressChunk: compressor(o.compression),
    useSummaryOffsets: o.summary, useStatistics: o.summary, useChunkIndex: o.summary,
    repeatSchemas: o.summary, repeatChannels: o.summary, useMessageIndex: o.summary,
    useAttachmentIndex: o.summary, useMetadataIndex: o.summary,
  });
  await writer.start({ profile: "ros2", library: "strata tests: @mcap/core" });
  const cloudWriter = new MessageWriter(parse(CLOUD, { ros2: true }));
  const tfWriter = new MessageWriter(parse(TF, { ros2: true }));
  const enc = new TextEncoder();
  const cloudSchema = await writer.registerSchema({ name: "sensor_msgs/msg/PointCloud2", encoding: "ros2msg", data: enc.encode(CLOUD) });
  const tfSchema = await writer.registerSchema({ name: "tf2_msgs/msg/TFMessage", encoding: "ros2msg", data: enc.encode(TF) });
  const channel = async (topic, schemaId) => writer.registerChannel({ topic, schemaId, messageEncoding: "cdr", metadata: new Map() });
  const cloudChannel = await channel("/velodyne_points", cloudSchema);
  const tfChannel = await channel("/tf", tfSchema);
  const staticChannel = await channel("/tf_static", tfSchema);
  let sequence = 0;
  const types = new Map([[cloudChannel, ["/velodyne_points", "sensor_msgs/msg/PointCloud2"]],
                         [tfChannel, ["/tf", "tf2_msgs/msg/TFMessage"]],
                         [staticChannel, ["/tf_static", "tf2_msgs/msg/TFMessage"]]]);
  const dumped = [];
  if (o.dump) fs.mkdirSync(o.dump, { recursive: true });
  const add = (channelId, ns, data) => {
    if (o.dump) {
      const file = `${String(dumped.length).padStart(6, "0")}.cdr`;
      fs.writeFileSync(path.join(o.dump, file), data);
      const [topic, type] = types.get(channelId);
      dumped.push(JSON.stringify({ topic, type, t: ns.toString(), file }));
    }
    return writer.addMessage({ channelId, sequence: sequence++, logTime: ns, publishTime: ns, data });
  };

  await add(staticChannel, stamps[0], tfWriter.writeMessage({ transforms: [transform("base_link", "velodyne", stamps[0], quaternion(MOUNT), MOUNT.map((r) => r[3]))] }));
  for (let k = 0; k < bins.length; ++k) {
    const raw = fs.readFileSync(path.join(o.seq, "velodyne", bins[k]));
    const n = raw.byteLength / 16;
    const withTime = o.pointTime === "t";
    const step = 1 + 4 + 12 + (withTime ? 4 : 0);
    const data = Buffer.alloc(n * step);
    for (let i = 0; i < n; ++i) {
      const x = raw.readFloatLE(16 * i), y = raw.readFloatLE(16 * i + 4), z = raw.readFloatLE(16 * i + 8);
      data.writeFloatLE(raw.readFloatLE(16 * i + 12), i * step);  // intensity, then a pad byte
      data.writeFloatLE(x, i * step + 5);
      data.writeFloatLE(y, i * step + 9);
      data.writeFloatLE(z, i * step + 13);
      if (withTime) data.writeUInt32LE(0, i * step + 17);
    }
    const fields = [
      { name: "intensity", offset: 0, datatype: 7, count: 1 },
      { name: "x", offset: 5, datatype: 7, count: 1 },
      { name: "y", offset: 9, datatype: 7, count: 1 },
      { name: "z", offset: 13, datatype: 7, count: 1 },
    ];
    if (withTime) fields.push({ name: "t", offset: 17, datatype: 6, count: 1 });
    await add(cloudChannel, stamps[k], cloudWriter.writeMessage({
      header: { stamp: stampOf(stamps[k]), frame_id: "velodyne" }, height: 1, width: n, fields,
      is_bigendian: false, point_step: step, row_step: step * n, data: new Uint8Array(data), is_dense: true,
    }));
    const steps = k + 1 < bins.length ? o.tfRate : 1;
    const q0 = quaternion(base[k]), p0 = [0, 1, 2].map((i) => base[k][i][3]);
    for (let s = 0; s < steps; ++s) {
      const a = s / steps;
      let q = q0, p = p0;
      if (s > 0) {
        const q1 = quaternion(base[k + 1]), p1 = [0, 1, 2].map((i) => base[k + 1][i][3]);
        q = slerp(q0, q1, a);
        p = p0.map((v, i) => (1 - a) * v + a * p1[i]);
      }
      const ns = stamps[k] + BigInt(Math.round(a * 1e8));
      await add(tfChannel, ns, tfWriter.writeMessage({ transforms: [transform("world", "base_link", ns, q, p)] }));
    }
  }
  await writer.end();
  fs.writeFileSync(o.out, Buffer.concat(chunks));
  if (o.dump) fs.writeFileSync(path.join(o.dump, "messages.jsonl"), dumped.join("\n") + "\n");
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
