// The live node test's independent subscriber (libs/ros2/tests/
// test_ros2_node.cpp): a ROS 2 participant of @foxglove/ros2 (its own RTPS
// and CDR, nothing of bims or Cyclone DDS) subscribes to bims-ros2's
// /bims/moving_mask (sensor_msgs/msg/Image) and /bims/odometry
// (nav_msgs/msg/Odometry), as a ROS 2 tool on the same machine would.
//
//   node subscribe_masks.mjs OUTDIR [QUIET_S]
//
// OUTDIR/received.csv: "sec,nsec,width,height,encoding,frame_id" of each
// mask; its pixels in masks/SEC_NSEC.pgm; odometry.txt: the odometry
// messages' count; OUTDIR/ready once both topics' publishers are
// connected. It ends QUIET_S seconds (default 10) after the last
// message (or after its start when none comes), or on SIGTERM.
import { parse } from "@foxglove/rosmsg";
import ros2 from "@foxglove/ros2";
import ros2nodejs from "@foxglove/ros2/nodejs.js";
import fs from "node:fs";

const [outDir, quietArg] = process.argv.slice(2);
const quietMs = 1000 * Number(quietArg ?? 10);
fs.mkdirSync(`${outDir}/masks`, { recursive: true });

const SEP = "\n================================================================================\n";
const TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
const HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
const IMAGE =
  "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n" +
  "uint8 is_bigendian\nuint32 step\nuint8[] data" + SEP + HEADER + SEP + TIME;
const ODOMETRY =
  "std_msgs/Header header\nstring child_frame_id\n" +
  "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist" +
  SEP + HEADER + SEP + TIME + SEP +
  "MSG: geometry_msgs/PoseWithCovariance\ngeometry_msgs/Pose pose\nfloat64[36] covariance" + SEP +
  "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation" + SEP +
  "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z" + SEP +
  "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w" + SEP +
  "MSG: geometry_msgs/TwistWithCovariance\ngeometry_msgs/Twist twist\nfloat64[36] covariance" + SEP +
  "MSG: geometry_msgs/Twist\ngeometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular" + SEP +
  "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z";

const { RosNode } = ros2;
const { getNetworkInterfaces, UdpSocketNode } = ros2nodejs;
const ros = new RosNode({
  name: "bims_test_subscriber",
  udpSocketCreate: UdpSocketNode.Create,
  getNetworkInterfaces,
  addresses: ["127.0.0.1"],
  log: process.env.BIMS_SUBSCRIBER_LOG ? console : undefined,
});
await ros.start();

let last = Date.now();
let odometry = 0;
const connected = new Set();
ros.on("discoveredPublication", (e) => {
  if (e.topicName !== "rt/bims/moving_mask" && e.topicName !== "rt/bims/odometry") return;
  connected.add(e.topicName);
  if (connected.size === 2) fs.writeFileSync(`${outDir}/ready`, "");
});
const csv = fs.openSync(`${outDir}/received.csv`, "w");
ros
  .subscribe({
    topic: "/bims/moving_mask",
    dataType: "sensor_msgs/msg/Image",
    msgDefinition: parse(IMAGE, { ros2: true }),
  })
  .on("message", (_t, m) => {
    last = Date.now();
    // @foxglove/rosmsg2-serialization reads builtin_interfaces/Time as
    // {sec, nsec}
    const { sec, nsec } = m.header.stamp;
    fs.writeSync(
      csv,
      `${sec},${nsec},${m.width},${m.height},${m.encoding},${m.header.frame_id}\n`,
    );
    if (m.data.length === m.width * m.height) {
      const head = Buffer.from(`P5\n${m.width} ${m.height}\n255\n`);
      fs.writeFileSync(`${outDir}/masks/${sec}_${nsec}.pgm`, Buffer.concat([head, m.data]));
    }
  });
ros
  .subscribe({
    topic: "/bims/odometry",
    dataType: "nav_msgs/msg/Odometry",
    msgDefinition: parse(ODOMETRY, { ros2: true }),
  })
  .on("message", () => {
    last = Date.now();
    odometry++;
  });

const end = async () => {
  fs.closeSync(csv);
  fs.writeFileSync(`${outDir}/odometry.txt`, `${odometry}\n`);
  await ros.shutdown();
  process.exit(0);
};
process.on("SIGTERM", () => void end());
const timer = setInterval(() => {
  if (Date.now() - last > quietMs) {
    clearInterval(timer);
    void end();
  }
}, 200);
