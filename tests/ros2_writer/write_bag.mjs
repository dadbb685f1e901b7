// The ROS 2 bag tests' independent writer (libs/bag/tests/test_ros2_import.cpp):
// MCAP files written by @mcap/core, messages serialized to CDR by
// @foxglove/rosmsg2-serialization, zstd by @foxglove/wasm-zstd, lz4 frames
// by lz4js; for a .db3, the serialized messages as a dump that
// write_db3.py puts into sqlite3. Nothing of bims is used to write them.
//
//   node write_bag.mjs SPEC.json
//
// SPEC: {out, format: "mcap" | "dump", compression: "" | "zstd" | "lz4" |
// any other name (the chunk's bytes left as they are), chunkSize,
// useChunks, summary, blob (the images' bytes), topics: [{name, type,
// schemaEncoding?, messageEncoding?}], messages: [{topic, logTime, msg,
// data?: [offset, length], truncate?}]}. A message's "data" field is the
// blob's bytes [offset, offset + length); "truncate" cuts its CDR bytes.
import { McapWriter } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "lz4js";
import fs from "node:fs";

const SEP = "\n================================================================================\n";
const DEFS = {
  "builtin_interfaces/Time": "int32 sec\nuint32 nanosec\n",
  "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
  "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z\n",
  "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
  "sensor_msgs/RegionOfInterest":
    "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n",
  "sensor_msgs/Image":
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n" +
    "uint8 is_bigendian\nuint32 step\nuint8[] data\n",
  "sensor_msgs/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data\n",
  "sensor_msgs/CameraInfo":
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n" +
    "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n" +
    "uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n",
  "sensor_msgs/Imu":
    "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n" +
    "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n" +
    "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n" +
    "float64[9] linear_acceleration_covariance\n",
  "sensor_msgs/MagneticField":
    "std_msgs/Header header\ngeometry_msgs/Vector3 magnetic_field\n" +
    "float64[9] magnetic_field_covariance\n",
};
const DEPS = {
  "std_msgs/Header": ["builtin_interfaces/Time"],
  "sensor_msgs/Image": ["std_msgs/Header"],
  "sensor_msgs/CompressedImage": ["std_msgs/Header"],
  "sensor_msgs/CameraInfo": ["std_msgs/Header", "sensor_msgs/RegionOfInterest"],
  "sensor_msgs/Imu": ["std_msgs/Header", "geometry_msgs/Quaternion", "geometry_msgs/Vector3"],
  "sensor_msgs/MagneticField": ["std_msgs/Header", "geometry_msgs/Vector3"],
};

/** The ros2msg schema text of "pkg/msg/Name": its definition, then each
 * type it uses after a separator line. */
function schemaText(type) {
  const base = type.replace("/msg/", "/");
  const seen = new Set();
  const order = [];
  const visit = (t) => {
    for (const d of DEPS[t] ?? []) {
      if (!seen.has(d)) {
        seen.add(d);
        order.push(d);
        visit(d);
      }
    }
  };
  visit(base);
  let text = DEFS[base];
  if (text === undefined) throw new Error(`no definition of ${type}`);
  for (const d of order) text += SEP + `MSG: ${d}\n` + DEFS[d];
  return text;
}

class FileWritable {
  constructor(path) {
    this.fd = fs.openSync(path, "w");
    this.pos = 0n;
  }
  position() {
    return this.pos;
  }
  async write(buffer) {
    fs.writeSync(this.fd, buffer);
    this.pos += BigInt(buffer.byteLength);
  }
  close() {
    fs.closeSync(this.fd);
  }
}

async function main() {
  const spec = JSON.parse(fs.readFileSync(process.argv[2], "utf8"));
  const blob = spec.blob ? fs.readFileSync(spec.blob) : Buffer.alloc(0);
  const writers = spec.topics.map((t) => new MessageWriter(parse(schemaText(t.type), { ros2: true })));
  const serialize = (m) => {
    const msg = m.msg;
    if (m.data) msg.data = new Uint8Array(blob.buffer, blob.byteOffset + m.data[0], m.data[1]);
    let bytes = writers[m.topic].writeMessage(msg);
    if (m.truncate !== undefined && m.truncate !== null) bytes = bytes.subarray(0, m.truncate);
    return bytes;
  };

  if (spec.format === "dump") {
    // for write_db3.py: topics, then each message's topic, time and bytes
    const parts = [];
    const index = [];
    let offset = 0;
    for (const m of spec.messages) {
      const b = serialize(m);
      parts.push(Buffer.from(b));
      index.push({ topic: m.topic, timestamp: m.logTime, offset, length: b.byteLength });
      offset += b.byteLength;
    }
    fs.writeFileSync(spec.out + ".bin", Buffer.concat(parts));
    fs.writeFileSync(
      spec.out + ".json",
      JSON.stringify({
        topics: spec.topics.map((t) => ({
          name: t.name,
          type: t.type,
          serialization_format: t.messageEncoding ?? "cdr",
        })),
        messages: index,
      }),
    );
    return;
  }

  await zstd.isLoaded;
  let compressChunk;
  const c = spec.compression ?? "";
  if (c === "zstd") compressChunk = (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 3) });
  else if (c === "lz4") compressChunk = (d) => ({ compression: "lz4", compressedData: lz4.compress(d) });
  else if (c !== "") compressChunk = (d) => ({ compression: c, compressedData: d });
  const out = new FileWritable(spec.out);
  const summary = spec.summary ?? true;
  const writer = new McapWriter({
    writable: out,
    useChunks: spec.useChunks ?? true,
    chunkSize: spec.chunkSize ?? 1024 * 1024,
    compressChunk,
    useStatistics: summary,
    useSummaryOffsets: summary,
    useChunkIndex: summary,
    useMessageIndex: summary,
    repeatSchemas: summary,
    repeatChannels: summary,
  });
  await writer.start({ profile: "ros2", library: "bims tests (@mcap/core)" });
  const channels = [];
  for (const t of spec.topics) {
    const schemaId = await writer.registerSchema({
      name: t.type,
      encoding: t.schemaEncoding ?? "ros2msg",
      data: new TextEncoder().encode(schemaText(t.type)),
    });
    channels.push(
      await writer.registerChannel({
        topic: t.name,
        schemaId,
        messageEncoding: t.messageEncoding ?? "cdr",
        metadata: new Map(),
      }),
    );
  }
  let sequence = 0;
  for (const m of spec.messages) {
    const t = BigInt(m.logTime);
    await writer.addMessage({
      channelId: channels[m.topic],
      sequence: sequence++,
      logTime: t,
      publishTime: t,
      data: serialize(m),
    });
  }
  await writer.end();
  out.close();
}

main().catch((e) => {
  console.error(e.stack ?? String(e));
  process.exit(1);
});
