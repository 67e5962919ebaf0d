#!/usr/bin/python3
"""Headless "display" for the VERNE simulation (LinuxCNC 2.9, Debian's python3 only).

linuxcnc runs it as: display.py -ini <inifile>. It drives the machine through the `linuxcnc`
module (estop reset, machine on, home all, teleop, auto, open, run, poll until idle), records
joint.N.pos-cmd with halsampler, reads pins with `halcmd getp`, writes <OUT_DIR>/result.json and
exits 0 when the scenario behaved as expected ([VERNE]EXPECT = ok | error), 1 otherwise.
LinuxCNC shuts down when this program exits and `linuxcnc` returns this exit status.
"""
import json
import os
import signal
import subprocess
import sys
import time

import linuxcnc

t_start = time.time()


def log(msg):
    print("[display %6.2fs] %s" % (time.time() - t_start, msg), flush=True)


ini_path = sys.argv[sys.argv.index("-ini") + 1]
ini = linuxcnc.ini(ini_path)
out_dir = ini.find("VERNE", "OUT_DIR")
expect = ini.find("VERNE", "EXPECT") or "ok"
timeout = float(ini.find("VERNE", "TIMEOUT") or 120)
program = ini.find("DISPLAY", "OPEN_FILE")
os.makedirs(out_dir, exist_ok=True)

s = linuxcnc.stat()
c = linuxcnc.command()
e = linuxcnc.error_channel()
errors = []           # every message read from the error channel
timeline = {}         # step name -> seconds since start
result = {"scenario": ini.find("VERNE", "SCENARIO"), "expect": expect, "program": program}


def drain_errors():
    while True:
        m = e.poll()
        if not m:
            return
        kind, text = m
        kinds = {linuxcnc.NML_ERROR: "NML_ERROR", linuxcnc.OPERATOR_ERROR: "OPERATOR_ERROR",
                 linuxcnc.NML_TEXT: "NML_TEXT", linuxcnc.OPERATOR_TEXT: "OPERATOR_TEXT",
                 linuxcnc.NML_DISPLAY: "NML_DISPLAY", linuxcnc.OPERATOR_DISPLAY: "OPERATOR_DISPLAY"}
        errors.append({"t": round(time.time() - t_start, 3), "kind": kinds.get(kind, str(kind)),
                       "text": text.strip()})
        log("error channel: %s %s" % (kinds.get(kind, kind), text.strip()))


def wait_for(what, pred, limit=10.0):
    t0 = time.time()
    while time.time() - t0 < limit:
        s.poll()
        drain_errors()
        if pred():
            timeline[what] = round(time.time() - t_start, 3)
            return True
        time.sleep(0.02)
    raise RuntimeError("timeout waiting for " + what)


def halcmd(*args):
    return subprocess.run(["halcmd"] + list(args), check=True, capture_output=True,
                          text=True).stdout.strip()


def getp(name):
    return halcmd("getp", name)


sampler_proc = None
ok = False
try:
    # 1. recording: start halsampler, then enable the sampler (so the FIFO never overruns)
    sample_file = os.path.join(out_dir, "samples.txt")
    sampler_proc = subprocess.Popen(["halsampler", "-t", sample_file])
    time.sleep(0.2)
    halcmd("setp", "sampler.0.enable", "1")

    # 2. estop reset, machine on
    c.state(linuxcnc.STATE_ESTOP_RESET)
    wait_for("estop-reset", lambda: s.task_state == linuxcnc.STATE_ESTOP_RESET)
    c.state(linuxcnc.STATE_ON)
    wait_for("machine-on", lambda: s.task_state == linuxcnc.STATE_ON)

    # 3. home all joints (immediate homing: HOME_SEARCH_VEL = 0)
    c.mode(linuxcnc.MODE_MANUAL)
    c.wait_complete()
    c.home(-1)
    c.wait_complete()
    wait_for("homed", lambda: all(s.homed[j] for j in range(s.joints)))
    result["kinematics_type"] = s.kinematics_type
    result["home_joints"] = list(s.joint_actual_position[:5])
    result["home_world"] = list(s.actual_position[:6])

    # 4. world mode (teleop), then auto
    c.teleop_enable(1)
    c.wait_complete()
    wait_for("teleop", lambda: s.motion_mode == linuxcnc.TRAJ_MODE_TELEOP)
    c.mode(linuxcnc.MODE_AUTO)
    c.wait_complete()
    wait_for("auto", lambda: s.task_mode == linuxcnc.MODE_AUTO)

    # 5. open and run the program
    c.program_open(program)
    c.wait_complete()
    c.auto(linuxcnc.AUTO_RUN, 0)
    wait_for("running", lambda: s.interp_state != linuxcnc.INTERP_IDLE or s.task_state != linuxcnc.STATE_ON, 5.0)
    wait_for("idle", lambda: s.interp_state == linuxcnc.INTERP_IDLE, timeout)
    time.sleep(0.3)        # let the last samples reach the FIFO
    s.poll()
    drain_errors()

    result["final_task_state"] = {linuxcnc.STATE_ESTOP: "ESTOP", linuxcnc.STATE_ESTOP_RESET: "ESTOP_RESET",
                                  linuxcnc.STATE_OFF: "OFF", linuxcnc.STATE_ON: "ON"}.get(s.task_state, s.task_state)
    result["final_exec_state"] = s.exec_state
    result["final_motion_line"] = s.motion_line
    result["final_current_line"] = s.current_line
    result["final_joints"] = list(s.joint_actual_position[:5])
    result["final_world"] = list(s.actual_position[:6])

    # 6. pins and parameters
    pins = {}
    for p in ["vernekins.fail-count", "vernekins.last-status", "vernekins.inverse-calls",
              "vernekins.forward-calls", "vernekins.tool-length", "vernekins.ik-branches",
              "vernekins.ik-fallbacks", "vernekins.fk-modes",
              "sampler.0.overruns", "sampler.0.sample-num", "motion.program-line",
              "motion.motion-enabled"] + ["joint.%d.pos-cmd" % j for j in range(5)]:
        pins[p] = getp(p)
    result["pins"] = pins
    log("pins: " + json.dumps(pins))
    halcmd("setp", "sampler.0.enable", "0")

    texts = " | ".join(m["text"] for m in errors)
    if expect == "ok":
        ok = (not [m for m in errors if m["kind"].endswith("ERROR")]
              and result["final_task_state"] == "ON"
              and int(pins["vernekins.fail-count"]) == 0)
    else:
        ok = "kinematicsInverse" in texts
except Exception as ex:      # noqa: BLE001 - report and fail
    log("FAILED: %r" % (ex,))
    result["exception"] = repr(ex)
    ok = False
finally:
    drain_errors()
    result["errors"] = errors
    result["timeline"] = timeline
    result["ok"] = ok
    if sampler_proc is not None:
        time.sleep(0.2)
        sampler_proc.send_signal(signal.SIGTERM)
        try:
            sampler_proc.wait(5)
        except subprocess.TimeoutExpired:
            sampler_proc.kill()
    with open(os.path.join(out_dir, "result.json"), "w") as f:
        json.dump(result, f, indent=1)
    log("scenario %s expect=%s -> %s" % (result["scenario"], expect, "PASS" if ok else "FAIL"))
    try:
        c.state(linuxcnc.STATE_OFF)
    except Exception:  # noqa: BLE001
        pass
sys.exit(0 if ok else 1)
