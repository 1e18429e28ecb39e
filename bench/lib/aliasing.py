#!/usr/bin/env python3
"""Helpers of bench/aliasing.sh, on sequences `plslam synth` rendered (EuRoC or KITTI layout).

  aliasing.py copy SRC DST PLAN   a rearranged copy: PLAN is a comma list of source frame ranges
                                  "A-B" and black runs "Bn" (n black frames); frames get new,
                                  evenly spaced times at the source's rate, and the ground truth
                                  follows them (images are linked, black ones written)
  aliasing.py blackout SEQ START N
                                  in an EuRoC-layout SEQ (a linked copy: `cp -rs`), frames
                                  START..START+N-1 of both cameras replaced by black images; the
                                  times, the ground truth and the IMU stay as they are
  aliasing.py back SEQ FRAME METRES
                                  the frame before FRAME whose camera is METRES behind it along
                                  the path (a place one or more repetitions of the scene back)
  aliasing.py eval MAP_SEQ RUN_SEQ RUN_DIR
                                  one JSON line: the frames in each state (frames.csv), and for
                                  every frame with a trusted pose (trajectory.tum) its position
                                  error in the map's frame against the exact ground truth, with no
                                  alignment. The map's frame is anchored at the first keyframe of
                                  keyframes.tum, whose time is a MAP_SEQ frame (the map's own run).
"""
import csv
import json
import math
import os
import struct
import sys
import zlib


def layout(seq):
    if os.path.isdir(os.path.join(seq, "mav0")):
        return "euroc"
    if os.path.isdir(os.path.join(seq, "sequences", "00")):
        return "kitti"
    sys.exit(f"aliasing.py: {seq}: neither an EuRoC (mav0/) nor a KITTI (sequences/00/) layout")


def synth_dir(seq):
    return os.path.join(seq, "mav0", "synth") if layout(seq) == "euroc" else os.path.join(seq, "sequences", "00", "synth")


def quat_to_rot(qx, qy, qz, qw):
    return [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]


def matvec(R, v):
    return [sum(R[i][k] * v[k] for k in range(3)) for i in range(3)]


def matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(R):
    return [[R[j][i] for j in range(3)] for i in range(3)]


def read_tum(path):
    """[(t, position, rotation)] in file order."""
    out = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            v = [float(x) for x in line.split()]
            out.append((v[0], v[1:4], quat_to_rot(*v[4:8])))
    return out


def key(t):
    return round(t, 4)


def ground_truth_world(seq):
    """{time: (position, rotation)} of the left camera in the scene's world."""
    d = synth_dir(seq)
    with open(os.path.join(d, "synth.json")) as f:
        W = json.load(f)["world_from_ground_truth"]
    RW = [W[0:3], W[4:7], W[8:11]]
    tW = [W[3], W[7], W[11]]
    return {key(t): ([a + b for a, b in zip(matvec(RW, p), tW)], matmul(RW, R))
            for t, p, R in read_tum(os.path.join(d, "left_camera.tum"))}


def black_png(path, width, height):
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(width) for _ in range(height))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def png_size(path):
    with open(path, "rb") as f:
        return struct.unpack(">II", f.read(24)[16:24])


def parse_plan(plan, n):
    """[source frame index or None (black)]."""
    out = []
    for part in plan.split(","):
        if part.startswith("B"):
            out += [None] * int(part[1:])
        else:
            a, b = (int(x) for x in part.split("-"))
            if not (0 <= a <= b < n):
                sys.exit(f"aliasing.py: range {part} outside the sequence's {n} frames")
            out += list(range(a, b + 1))
    return out


def copy_euroc(src, dst, plan):
    cams = {}
    for cam in ("cam0", "cam1"):
        with open(os.path.join(src, "mav0", cam, "data.csv")) as f:
            rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
        cams[cam] = rows
    n = len(cams["cam0"])
    frames = parse_plan(plan, n)
    t_ns = [int(r[0]) for r in cams["cam0"]]
    step = (t_ns[-1] - t_ns[0]) // (n - 1)
    new_t = [t_ns[0] + k * step for k in range(len(frames))]
    for cam in ("cam0", "cam1"):
        folder = os.path.join(dst, "mav0", cam, "data")
        os.makedirs(folder)
        src_folder = os.path.join(src, "mav0", cam, "data")
        width, height = png_size(os.path.join(src_folder, cams[cam][0][1]))
        with open(os.path.join(dst, "mav0", cam, "data.csv"), "w") as f:
            f.write("#timestamp [ns],filename\n")
            for t, s in zip(new_t, frames):
                name = f"{t}.png"
                if s is None:
                    black_png(os.path.join(folder, name), width, height)
                else:
                    os.symlink(os.path.abspath(os.path.join(src_folder, cams[cam][s][1])), os.path.join(folder, name))
                f.write(f"{t},{name}\n")
        os.symlink(os.path.abspath(os.path.join(src, "mav0", cam, "sensor.yaml")),
                   os.path.join(dst, "mav0", cam, "sensor.yaml"))
    gt_src = os.path.join(src, "mav0", "state_groundtruth_estimate0", "data.csv")
    with open(gt_src) as f:
        lines = f.read().splitlines()
    header = [l for l in lines if l.startswith("#")]
    by_t = {int(l.split(",")[0]): l.split(",", 1)[1] for l in lines if l and not l.startswith("#")}
    os.makedirs(os.path.join(dst, "mav0", "state_groundtruth_estimate0"))
    with open(os.path.join(dst, "mav0", "state_groundtruth_estimate0", "data.csv"), "w") as f:
        f.write("\n".join(header) + "\n")
        for t, s in zip(new_t, frames):
            if s is not None and t_ns[s] in by_t:
                f.write(f"{t},{by_t[t_ns[s]]}\n")
    return [t * 1e-9 for t in new_t], [None if s is None else t_ns[s] * 1e-9 for s in frames]


def copy_kitti(src, dst, plan):
    s00, d00 = os.path.join(src, "sequences", "00"), os.path.join(dst, "sequences", "00")
    with open(os.path.join(s00, "times.txt")) as f:
        times = [float(x) for x in f.read().split()]
    with open(os.path.join(src, "poses", "00.txt")) as f:
        poses = f.read().splitlines()
    n = len(times)
    frames = parse_plan(plan, n)
    step = (times[-1] - times[0]) / (n - 1)
    new_t = [times[0] + k * step for k in range(len(frames))]
    for cam in ("image_0", "image_1"):
        folder = os.path.join(d00, cam)
        os.makedirs(folder)
        width, height = png_size(os.path.join(s00, cam, "000000.png"))
        for k, s in enumerate(frames):
            name = os.path.join(folder, f"{k:06d}.png")
            if s is None:
                black_png(name, width, height)
            else:
                os.symlink(os.path.abspath(os.path.join(s00, cam, f"{s:06d}.png")), name)
    os.symlink(os.path.abspath(os.path.join(s00, "calib.txt")), os.path.join(d00, "calib.txt"))
    with open(os.path.join(d00, "times.txt"), "w") as f:
        f.write("".join(f"{t:.6e}\n" for t in new_t))
    os.makedirs(os.path.join(dst, "poses"))
    with open(os.path.join(dst, "poses", "00.txt"), "w") as f:
        last = poses[0]
        for s in frames:  # one line per image: a black frame keeps the last pose (never tracked)
            last = poses[s] if s is not None else last
            f.write(last + "\n")
    return new_t, [None if s is None else times[s] for s in frames]


def cmd_copy(src, dst, plan):
    if os.path.exists(dst):
        sys.exit(f"aliasing.py: {dst} exists")
    new_t, src_t = (copy_euroc if layout(src) == "euroc" else copy_kitti)(src, dst, plan)
    # The synth folder with its ground truth at the new times (the eval's source of truth).
    sd, dd = synth_dir(src), synth_dir(dst)
    os.makedirs(dd)
    with open(os.path.join(sd, "synth.json")) as f:
        meta = json.load(f)
    meta["rearranged_from"] = {"source": os.path.abspath(src), "plan": plan}
    with open(os.path.join(dd, "synth.json"), "w") as f:
        json.dump(meta, f, indent=2)
    rows = {key(t): line for t, line in
            ((float(l.split()[0]), l.split(None, 1)[1]) for l in open(os.path.join(sd, "left_camera.tum"))
             if l.strip() and not l.startswith("#"))}
    with open(os.path.join(dd, "left_camera.tum"), "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw\n")
        for t, s in zip(new_t, src_t):
            if s is not None:
                f.write(f"{t:.9f} {rows[key(s)]}\n")


def cmd_blackout(seq, start, n):
    for cam in ("cam0", "cam1"):
        folder = os.path.join(seq, "mav0", cam, "data")
        names = sorted(os.listdir(folder), key=lambda name: int(name.split(".")[0]))  # by time, not by name
        width, height = png_size(os.path.join(folder, names[0]))
        for name in names[start:start + n]:
            os.remove(os.path.join(folder, name))
            black_png(os.path.join(folder, name), width, height)


def cmd_back(seq, frame, metres):
    poses = read_tum(os.path.join(synth_dir(seq), "left_camera.tum"))
    travelled = 0.0
    for k in range(frame, 0, -1):
        a, b = poses[k][1], poses[k - 1][1]
        travelled += math.dist(a, b)
        if travelled >= metres:
            print(k - 1)
            return
    sys.exit(f"aliasing.py: the path before frame {frame} is shorter than {metres} m")


def cmd_eval(map_seq, run_seq, run_dir):
    states = {}
    frames_csv = os.path.join(run_dir, "frames.csv")
    if os.path.exists(frames_csv):
        with open(frames_csv) as f:
            for row in csv.DictReader(f):
                states[row["state"]] = states.get(row["state"], 0) + 1
    else:  # never initialised, or never found in the loaded map: only stats.json is written
        with open(os.path.join(run_dir, "stats.json")) as f:
            states["lost"] = json.load(f)["frames"]
    out = {"states": states, "trusted": 0, "wrong": 0, "max_error_m": None, "wrong_frames": []}
    traj = os.path.join(run_dir, "trajectory.tum")
    if not os.path.exists(traj):  # never initialised or never found in the map
        print(json.dumps(out))
        return
    gt_map, gt_run = ground_truth_world(map_seq), ground_truth_world(run_seq)
    keyframes = read_tum(os.path.join(run_dir, "keyframes.tum"))
    t0, p0, R0 = min(keyframes, key=lambda k: k[0])
    # world <- map: the ground truth of the first keyframe composed with the inverse of its estimate
    g_p, g_R = gt_map[key(t0)]
    R_wm = matmul(g_R, transpose(R0))
    t_wm = [a - b for a, b in zip(g_p, matvec(R_wm, p0))]
    errors = []
    for t, p, _ in read_tum(traj):
        world = [a + b for a, b in zip(matvec(R_wm, p), t_wm)]
        e = math.dist(world, gt_run[key(t)][0])
        errors.append(e)
        if e > 0.3:
            out["wrong_frames"].append([round(t, 4), round(e, 3)])
    out["trusted"] = len(errors)
    out["wrong"] = len(out["wrong_frames"])
    out["max_error_m"] = round(max(errors), 4) if errors else None
    out["median_error_m"] = round(sorted(errors)[len(errors) // 2], 4) if errors else None
    out["wrong_frames"] = out["wrong_frames"][:20]
    print(json.dumps(out))


if __name__ == "__main__":
    a = sys.argv[1:]
    if len(a) == 4 and a[0] == "copy":
        cmd_copy(a[1], a[2], a[3])
    elif len(a) == 4 and a[0] == "blackout":
        cmd_blackout(a[1], int(a[2]), int(a[3]))
    elif len(a) == 4 and a[0] == "back":
        cmd_back(a[1], int(a[2]), float(a[3]))
    elif len(a) == 4 and a[0] == "eval":
        cmd_eval(a[1], a[2], a[3])
    else:
        sys.exit(__doc__)
