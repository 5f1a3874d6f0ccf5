#!/usr/bin/env python3
"""Reads a recording's motion files back with Python's csv and yaml modules.

Usage: read_motion_files.py RECORDING_DIR.  Exits 1 with one line naming the
file and what was wrong, 0 when every file has its layout, its time stamps
increase by whole sample periods, and the readings are plausible.
"""
import csv
import math
import sys

import yaml


def fail(path, what):
    print(f"{path}: {what}")
    sys.exit(1)


def numbers(path, row, n):
    if len(row) != n:
        fail(path, f"expected {n} columns, got {len(row)}: {row}")
    try:
        return [float(v) for v in row]
    except ValueError:
        fail(path, f"expected numbers: {row}")


def read_csv(path, n):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or not rows[0][0].startswith("#timestamp [ns]") or len(rows[0]) != n:
        fail(path, "expected a '#timestamp [ns],...' header of %d columns" % n)
    return [numbers(path, r, n) for r in rows[1:]]


def read_txt(path, n):
    with open(path) as f:
        return [numbers(path, line.split(), n) for line in f if not line.startswith("#")]


def check_period(path, stamps, rate_hz, scale):
    if not stamps:
        fail(path, "no readings")
    for a, b in zip(stamps, stamps[1:]):
        if abs((b - a) * scale - 1.0 / rate_hz) > 2e-6:
            fail(path, f"time stamps {a} and {b} are not one period of {rate_hz} Hz apart")


def main(d):
    imu_yaml = yaml.safe_load(open(f"{d}/imu.yaml"))
    for k in ("update_rate", "accelerometer_noise_density", "accelerometer_random_walk",
              "gyroscope_noise_density", "gyroscope_random_walk"):
        if not isinstance(imu_yaml.get(k), (int, float)):
            fail(f"{d}/imu.yaml", f"{k} is not a number")
    robot = yaml.safe_load(open(f"{d}/robot.yaml"))
    for k in ("T_b_c", "T_b_i"):
        if len(robot.get(k, [])) != 16 or robot[k][15] != 1:
            fail(f"{d}/robot.yaml", f"{k} is not a 4 x 4 transform")
    truth = yaml.safe_load(open(f"{d}/robot_truth.yaml"))
    if abs(truth["nominal_wheel_radius_m"] - robot["wheel_radius_m"]) > 1e-12:
        fail(f"{d}/robot_truth.yaml", "nominal radius differs from robot.yaml's")

    imu = read_csv(f"{d}/imu0/data.csv", 7)
    check_period(f"{d}/imu0/data.csv", [r[0] for r in imu], imu_yaml["update_rate"], 1e-9)
    g = sorted(math.sqrt(r[4] ** 2 + r[5] ** 2 + r[6] ** 2) for r in imu)[len(imu) // 2]
    if not 9.0 < g < 10.6:
        fail(f"{d}/imu0/data.csv", f"median specific force {g} m/s^2, not about g")
    accel = read_txt(f"{d}/accelerometer.txt", 4)
    if len(accel) != len(imu) or any(abs(a[0] - i[0] * 1e-9) > 1e-6 for a, i in zip(accel, imu)):
        fail(f"{d}/accelerometer.txt", "not the IMU's readings on the frames' clock")
    if len(read_csv(f"{d}/imu0/truth.csv", 13)) != len(imu):
        fail(f"{d}/imu0/truth.csv", "not one line a reading")

    wheels = read_csv(f"{d}/wheels.csv", 3)
    check_period(f"{d}/wheels.csv", [r[0] for r in wheels], robot["encoder_rate_hz"], 1e-9)
    if wheels[-1][1] <= wheels[0][1]:
        fail(f"{d}/wheels.csv", "the left wheel did not turn forward")
    if len(read_csv(f"{d}/wheels_truth.csv", 10)) != len(wheels):
        fail(f"{d}/wheels_truth.csv", "not one line a reading")
    odom = read_txt(f"{d}/odom.txt", 14)
    if len(odom) != len(wheels) or odom[-1][1] <= 0:
        fail(f"{d}/odom.txt", "not one pose a reading, or no forward motion")
    if len(read_txt(f"{d}/groundtruth.txt", 8)) == 0:
        fail(f"{d}/groundtruth.txt", "no poses")
    print(f"{d}: {len(imu)} IMU readings, {len(wheels)} encoder readings, all read back")


if __name__ == "__main__":
    main(sys.argv[1])
