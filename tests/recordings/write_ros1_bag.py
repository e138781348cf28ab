#!/usr/bin/env python3
"""Writes a ROS 1 bag from a KITTI-layout folder with Debian's python3-rosbag: an independent
writer of the recordings strata's tests read (tests/recordings/). Nothing of strata is used.

  write_ros1_bag.py SEQ OUT.bag [--compression none|bz2|lz4] [--frames A:B] [--chunk-kb N]
                    [--point-time none|t|time|timestamp|offset_time] [--float64] [--big-endian]
                    [--extra-cloud-topic] [--tf-rate K] [--tf-from K] [--odom] [--rename-x]
                    [--motion END_POSES] [--imu UX,UY,UZ]

SEQ holds velodyne/NNNNNN.bin (float32 x y z intensity), poses.txt (camera 0 in the world, 3x4
per line) and calib.txt (Tr: velodyne to camera 0); the velodyne in the world is
inv(Tr) P Tr (the world frame is the first velodyne's, as SemanticKITTI's tools use it). Each scan becomes a sensor_msgs/PointCloud2
on /velodyne_points in frame "velodyne", stamped 0.1 s apart from t0; /tf carries world ->
base_link (K poses per scan interval, linearly interpolated between the scans' poses, so that the
composed pose at each scan's stamp is the scan's own); /tf_static carries base_link -> velodyne,
a fixed mounting. --odom writes the trajectory as nav_msgs/Odometry on /odom instead of /tf.
--point-time adds a per-point time field (all points at the stamp, in that field's convention).
--tf-from K leaves out the trajectory before scan K; --rename-x calls the x field "q" (broken
recordings for the tests of refusals).
--motion END_POSES: sweeps recorded while moving (strata's simulator with motion). Each scan has
velodyne/NNNNNN.time (float32 seconds after the stamp, per point) and END_POSES the sensor's pose
one revolution (0.1 s) after the stamp (3x4 per line, as poses.txt); the stamps come from
times.txt, and /tf gets K poses across each sweep from its start to its end pose.
--imu UX,UY,UZ: an IMU on /imu/data (sensor_msgs/Imu, 100 Hz, frame imu_link mounted upside
down and turned 90 degrees on base_link, on /tf_static) over the drive, up being (UX, UY, UZ) in
the poses' world frame: the accelerometer reads g up (plus the vehicle's acceleration, taken
from the poses) and the gyro the turn rate, each with seeded white noise (0.05 m/s^2,
0.002 rad/s); no orientation (its covariance -1, as REP 145 says for an IMU without one).
"""
import argparse
import os

import numpy as np
import rosbag
import genpy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, PointCloud2, PointField
from std_msgs.msg import Header
from tf2_msgs.msg import TFMessage

T0 = 1317029540  # seconds: a KITTI-era epoch time
# base_link -> velodyne: 1.2 m forward, 1.73 m up, yawed 2 degrees (any rigid mounting will do).
MOUNT_YAW = np.radians(2.0)
MOUNT = np.array([[np.cos(MOUNT_YAW), -np.sin(MOUNT_YAW), 0.0, 1.2],
                  [np.sin(MOUNT_YAW), np.cos(MOUNT_YAW), 0.0, 0.0],
                  [0.0, 0.0, 1.0, 1.73],
                  [0.0, 0.0, 0.0, 1.0]])


def read_matrix(line):
    m = np.eye(4)
    m[:3, :4] = np.array([float(v) for v in line.split()[-12:]]).reshape(3, 4)
    return m


def quaternion(r):
    """x, y, z, w of a rotation matrix (Shepperd's method)."""
    t = np.trace(r)
    if t > 0:
        s = np.sqrt(t + 1.0) * 2
        return ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, 0.25 * s)
    i = int(np.argmax(np.diag(r)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]) * 2
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (r[j, i] + r[i, j]) / s
    q[k] = (r[k, i] + r[i, k]) / s
    q[3] = (r[k, j] - r[j, k]) / s
    return tuple(q)


# base_link -> imu_link: upside down (rolled 180 degrees) and yawed 90, 0.3 m ahead and 0.5 m up.
IMU_MOUNT = np.array([[0.0, 1.0, 0.0, 0.3],
                      [1.0, 0.0, 0.0, 0.0],
                      [0.0, 0.0, -1.0, 0.5],
                      [0.0, 0.0, 0.0, 1.0]])
G = 9.80665  # m/s^2


def rotation_vector(r):
    """The axis times the angle of a rotation matrix (small and moderate angles)."""
    angle = np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0))
    w = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return w * (0.5 if angle < 1e-9 else angle / (2.0 * np.sin(angle)))


def pose_at(knots, poses, t):
    """The pose at time t, interpolated between the knots around it (held past the ends)."""
    k = int(np.clip(np.searchsorted(knots, t) - 1, 0, len(knots) - 2))
    a = float(np.clip((t - knots[k]) / (knots[k + 1] - knots[k]), 0.0, 1.0))
    q = slerp(quaternion(poses[k][:3, :3]), quaternion(poses[k + 1][:3, :3]), a)
    m = np.eye(4)
    x, y, z, w = q
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = (1 - a) * poses[k][:3, 3] + a * poses[k + 1][:3, 3]
    return m


def write_imu(bag, knots, poses, up):
    """100 Hz readings of an IMU at IMU_MOUNT on base_link, which moves through `poses` at
    times `knots` (seconds after T0)."""
    rng = np.random.default_rng(20261205)
    dt = 0.01
    up = np.asarray(up, dtype=float) / np.linalg.norm(up)
    for t in np.arange(knots[0], knots[-1], dt):
        imu = [pose_at(knots, poses, t + d) @ IMU_MOUNT for d in (-dt, 0.0, dt)]
        r = imu[1][:3, :3]
        accel = (imu[2][:3, 3] - 2 * imu[1][:3, 3] + imu[0][:3, 3]) / (dt * dt)
        f = r.T @ (G * up + accel) + rng.normal(0.0, 0.05, 3)
        w = rotation_vector(r.T @ imu[2][:3, :3]) / dt + rng.normal(0.0, 0.002, 3)
        msg = Imu()
        stamp = genpy.Time(T0) + genpy.Duration.from_sec(t)
        msg.header = Header(stamp=stamp, frame_id='imu_link')
        msg.orientation_covariance[0] = -1.0
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = w
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = f
        bag.write('/imu/data', msg, stamp)


def slerp(q0, q1, a):
    q0, q1 = np.array(q0), np.array(q1)
    d = float(np.dot(q0, q1))
    if d < 0:
        q1, d = -q1, -d
    if d > 0.9995:
        q = q0 + a * (q1 - q0)
        return q / np.linalg.norm(q)
    th = np.arccos(d)
    return (np.sin((1 - a) * th) * q0 + np.sin(a * th) * q1) / np.sin(th)


def transform(parent, child, stamp, m=None, q=None, p=None):
    t = TransformStamped()
    t.header = Header(stamp=stamp, frame_id=parent)
    t.child_frame_id = child
    if m is not None:
        q, p = quaternion(m[:3, :3]), m[:3, 3]
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = p
    (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
     t.transform.rotation.w) = q
    return t


TIME_FIELDS = {  # name: (datatype, numpy type, values of points `dt` seconds after the stamp)
    't': (PointField.UINT32, 'u4', lambda stamp, dt: np.round(dt * 1e9)),
    'time': (PointField.FLOAT32, 'f4', lambda stamp, dt: dt),
    'timestamp': (PointField.FLOAT64, 'f8', lambda stamp, dt: stamp.to_sec() + dt),
    'offset_time': (PointField.UINT32, 'u4', lambda stamp, dt: np.round(dt * 1e9)),
}


def cloud(points, stamp, args, dts):
    msg = PointCloud2()
    msg.header = Header(stamp=stamp, frame_id='velodyne')
    msg.height, msg.width = 1, len(points)
    endian = '>' if args.big_endian else '<'
    coord, size = ('f8', 8) if args.float64 else ('f4', 4)
    ctype = PointField.FLOAT64 if args.float64 else PointField.FLOAT32
    # intensity first and a pad byte: the layout must be found by name, not assumed.
    fields = [PointField('intensity', 0, PointField.FLOAT32, 1)]
    layout = {'names': ['intensity'], 'formats': [endian + 'f4'], 'offsets': [0]}
    offset = 5
    for name in ('q' if args.rename_x else 'x', 'y', 'z'):
        fields.append(PointField(name, offset, ctype, 1))
        layout['names'].append(name)
        layout['formats'].append(endian + coord)
        layout['offsets'].append(offset)
        offset += size
    if args.point_time != 'none':
        datatype, ttype, _ = TIME_FIELDS[args.point_time]
        fields.append(PointField(args.point_time, offset, datatype, 1))
        layout['names'].append(args.point_time)
        layout['formats'].append(endian + ttype)
        layout['offsets'].append(offset)
        offset += np.dtype(ttype).itemsize
    layout['itemsize'] = offset
    msg.fields = fields
    msg.is_bigendian = args.big_endian
    msg.point_step = offset
    msg.row_step = msg.point_step * len(points)
    # One structured array in exactly the layout the fields describe (the pad byte zero).
    data = np.zeros(len(points), dtype=np.dtype(layout))
    data['intensity'] = points[:, 3]
    for column, name in enumerate(layout['names'][1:4]):
        data[name] = points[:, column]
    if args.point_time != 'none':
        data[args.point_time] = TIME_FIELDS[args.point_time][2](stamp, np.asarray(dts, dtype=np.float64))
    msg.data = data.tobytes()
    msg.is_dense = True
    return msg


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('seq')
    ap.add_argument('out')
    ap.add_argument('--compression', default='none', choices=['none', 'bz2', 'lz4'])
    ap.add_argument('--frames', default='')
    ap.add_argument('--chunk-kb', type=int, default=768)
    ap.add_argument('--point-time', default='none', choices=['none'] + sorted(TIME_FIELDS))
    ap.add_argument('--float64', action='store_true')
    ap.add_argument('--big-endian', action='store_true')
    ap.add_argument('--extra-cloud-topic', action='store_true')
    ap.add_argument('--tf-rate', type=int, default=1)
    ap.add_argument('--tf-from', type=int, default=0)
    ap.add_argument('--odom', action='store_true')
    ap.add_argument('--rename-x', action='store_true')
    ap.add_argument('--motion', default='')
    ap.add_argument('--imu', default='')
    args = ap.parse_args()

    tr = np.eye(4)
    calib = os.path.join(args.seq, 'calib.txt')
    if os.path.exists(calib):
        with open(calib) as f:
            tr = next((read_matrix(l) for l in f if l.startswith('Tr:')), tr)
    with open(os.path.join(args.seq, 'poses.txt')) as f:
        cams = [read_matrix(l) for l in f if l.strip()]
    bins = sorted(f for f in os.listdir(os.path.join(args.seq, 'velodyne')) if f.endswith('.bin'))
    a, _, b = args.frames.partition(':')
    first = int(a) if a else 0
    last = int(b) if b else len(bins)
    frames = range(first, last)
    # The sensor in the world, then the vehicle (base_link) under it through the mounting.
    base = [np.linalg.inv(tr) @ cams[i] @ tr @ np.linalg.inv(MOUNT) for i in frames]
    stamps = [genpy.Time(T0) + genpy.Duration.from_sec(0.1 * k) for k in range(len(base))]
    ends = None
    if args.motion:
        with open(args.motion) as f:
            end_cams = [read_matrix(l) for l in f if l.strip()]
        ends = [np.linalg.inv(tr) @ end_cams[i] @ tr @ np.linalg.inv(MOUNT) for i in frames]
        with open(os.path.join(args.seq, 'times.txt')) as f:
            times = [float(l) for l in f if l.strip()]
        stamps = [genpy.Time(T0) + genpy.Duration.from_sec(times[i]) for i in frames]

    bag = rosbag.Bag(args.out, 'w', compression=args.compression,
                     chunk_threshold=args.chunk_kb * 1024)
    try:
        mounts = [transform('base_link', 'velodyne', stamps[0], m=MOUNT)]
        if args.imu:
            mounts.append(transform('base_link', 'imu_link', stamps[0], m=IMU_MOUNT))
        bag.write('/tf_static', TFMessage(mounts), stamps[0])
        if args.imu:
            knots = [(s - genpy.Time(T0)).to_sec() for s in stamps]
            poses = list(base)
            if ends is not None:  # the last sweep's end
                knots.append(knots[-1] + 0.1)
                poses.append(ends[-1])
            write_imu(bag, knots, poses, [float(v) for v in args.imu.split(',')])
        for k, i in enumerate(frames):
            points = np.fromfile(os.path.join(args.seq, 'velodyne', bins[i]),
                                 dtype=np.float32).reshape(-1, 4)
            dts = np.zeros(len(points))
            if ends is not None:
                dts = np.fromfile(os.path.join(args.seq, 'velodyne', bins[i][:-4] + '.time'),
                                  dtype=np.float32)
            msg = cloud(points, stamps[k], args, dts)
            bag.write('/velodyne_points', msg, stamps[k])
            if args.extra_cloud_topic:
                bag.write('/velodyne_points_copy', msg, stamps[k])
            if k < args.tf_from:
                continue
            # K poses from this scan's to the next one's (the last scan: its own alone), or with
            # --motion K + 1 across the sweep, from its start to its end pose.
            if ends is not None:
                target, steps, last = ends[k], args.tf_rate, True
            else:
                target = base[k + 1] if k + 1 < len(base) else None
                steps, last = (args.tf_rate, False) if target is not None else (1, False)
            q0, p0 = quaternion(base[k][:3, :3]), base[k][:3, 3]
            for s in range(steps + (1 if last else 0)):
                alpha = s / steps
                if s == 0:
                    q, p = q0, p0
                else:
                    q1, p1 = quaternion(target[:3, :3]), target[:3, 3]
                    q, p = tuple(slerp(q0, q1, alpha)), (1 - alpha) * p0 + alpha * p1
                t = stamps[k] + genpy.Duration.from_sec(0.1 * alpha)
                if args.odom:
                    o = Odometry()
                    o.header = Header(stamp=t, frame_id='world')
                    o.child_frame_id = 'base_link'
                    o.pose.pose.position.x, o.pose.pose.position.y, o.pose.pose.position.z = p
                    (o.pose.pose.orientation.x, o.pose.pose.orientation.y,
                     o.pose.pose.orientation.z, o.pose.pose.orientation.w) = q
                    bag.write('/odom', o, t)
                else:
                    bag.write('/tf', TFMessage([transform('world', 'base_link', t, q=q, p=p)]), t)
    finally:
        bag.close()


if __name__ == '__main__':
    main()
