#!/usr/bin/env python3
"""The machine scene ends a run that cannot finish: a stop request (SIGTERM)
and &integrator max_wall_time reach the integration between its steps, in
the run and in Benettin's exponent, with the documented exit code and no
file written (an existing one is left as it was).

  stall-wall-time   the rate-and-state slider started far from balance (the
                    spring 600 N/m set for 450: the slip rate falls to 1e-18
                    m/s, a time scale m v/(N a) of 1e-16 s) on the explicit
                    rkf45, whose steps fall below it inside one output
                    interval, with max_wall_time = 1 s: exit 4 within the
                    limit and a margin, the message names max_wall_time
  stall-signal      the same run without a limit, SIGTERM after 1 s: exit 6
                    within a second, an existing output file untouched
  benettin-wall-time  a cheap arctan-law run whose Benettin exponent
                    renormalises 1e6 times, max_wall_time = 1 s: the run
                    ends in a fraction of the limit, Benettin at the limit
  sweep-signal      a sweep whose one point is that stalled slider, SIGTERM
                    inside the point: exit 6 within the margin, the file
                    written whole over the one it replaces with the point
                    pending (status 0: a resume computes it)

    machine_guard.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import argparse
import signal
import subprocess
import sys
import time
from pathlib import Path

# The far-from-balance start of docs/laws.md: x0 balances mu0 N with 450 N/m, the spring is 600 N/m,
# on an explicit stepper (rodas4 runs it to the end in some 0.1 s; rkf45 reached t = 0.14 s of 1500
# in 3 s, measured).
METHOD = ["--set", "integrator.method='rkf45'"]
STALL = ["--set", "machine.stiffness=600.0"] + METHOD
# The time a stopped run may take beyond its limit or its signal: one watch interval (16 steps, or
# 0.05 s between looks at a stop request) is microseconds to 0.05 s; the rest is the process's start
# and end (reading the input, HDF5's library), some 0.1 s on a loaded machine.  3 s leaves room for
# a machine shared by many builds without letting a hang (the run never ends) pass.
MARGIN = 3.0


def command(args, out, extra):
    return [args.binary, "-o", str(out), str(Path(args.inputs) / "machine_rate_state.nml")] + extra


def finished(process, limit):
    try:
        _, stderr = process.communicate(timeout=limit)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        raise AssertionError(f"still running {limit:.1f} s later: the guard did not reach the integration")
    return stderr


def stall_wall_time(args):
    out = Path(args.workdir) / "stall.h5"
    out.unlink(missing_ok=True)
    start = time.monotonic()
    process = subprocess.Popen(command(args, out, STALL + ["--set", "integrator.max_wall_time=1.0"]),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stderr = finished(process, 1.0 + MARGIN)
    took = time.monotonic() - start
    print(f"stall-wall-time: exit {process.returncode} after {took:.2f} s: {stderr.strip()}")
    assert process.returncode == 4, process.returncode
    assert "max_wall_time = 1" in stderr and "rate_state law" in stderr, stderr
    assert not out.exists(), "a file was written"


def catches_sigterm(pid):
    """Whether process pid has a handler for SIGTERM (Linux: SigCgt of /proc/PID/status)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("SigCgt:"):
                return bool(int(line.split()[1], 16) >> (signal.SIGTERM - 1) & 1)
    except OSError:
        return False
    return False


def stall_signal(args):
    out = Path(args.workdir) / "kept.h5"
    out.write_bytes(b"an existing file the stopped run must leave as it was\n")
    before = out.read_bytes()
    process = subprocess.Popen(command(args, out, STALL + ["--force"]), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    # Signal once the program catches SIGTERM (its handler goes in at the run's first look at a stop
    # request, within 16 steps of the start): no timing assumption; then the run is in the stall
    # (it begins 0.1 s in) or soon will be.
    deadline = time.monotonic() + 60
    while not catches_sigterm(process.pid) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(0.5)
    assert process.poll() is None, "the stalled run ended by itself"
    sent = time.monotonic()
    process.send_signal(signal.SIGTERM)
    stderr = finished(process, MARGIN)
    took = time.monotonic() - sent
    print(f"stall-signal: exit {process.returncode} {took:.2f} s after SIGTERM: {stderr.strip()}")
    assert process.returncode == 6, process.returncode
    assert "stopped on request" in stderr, stderr
    assert out.read_bytes() == before, "the existing file was changed"


def benettin_wall_time(args):
    out = Path(args.workdir) / "benettin.h5"
    out.unlink(missing_ok=True)
    sets = ["--set", "law.model='arctan'", "--set", "law.epsilon=1.0e4", "--set", "machine.damping=0.5",
            "--set", "machine.belt_velocity=0.1", "--set", "machine.load_velocity=0.0",
            "--set", "machine.x0=0.0", "--set", "machine.v0=0.1", "--set", "machine.stiffness=2.0",
            "--set", "machine.t_end=1000.0", "--set", "machine.dt_out=1.0",
            "--set", "analysis.lyapunov=.true.", "--set", "analysis.lyapunov_transient=0.0",
            "--set", "analysis.lyapunov_renormalise=1.0e-3", "--set", "analysis.window_start=0.0",
            "--set", "analysis.window_end=1000.0", "--set", "integrator.max_wall_time=1.0"]
    start = time.monotonic()
    process = subprocess.Popen(command(args, out, sets), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stderr = finished(process, 1.0 + MARGIN)
    took = time.monotonic() - start
    print(f"benettin-wall-time: exit {process.returncode} after {took:.2f} s: {stderr.strip()}")
    assert process.returncode == 4, process.returncode
    assert "Benettin" in stderr and "max_wall_time = 1" in stderr, stderr
    assert not out.exists(), "a file was written"


def sweep_signal(args):
    import h5py

    out = Path(args.workdir) / "sweep.h5"
    out.write_bytes(b"an earlier output the interrupted sweep replaces only with a whole file\n")
    sweep = Path(args.workdir) / "one_point.nml"
    sweep.write_text("&sweep sweep_variable = 'machine.stiffness', sweep_values = 600.0 /\n")
    process = subprocess.Popen(command(args, out, [str(sweep), "--force"] + METHOD), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not catches_sigterm(process.pid) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(0.5)
    assert process.poll() is None, "the stalled point ended by itself"
    sent = time.monotonic()
    process.send_signal(signal.SIGTERM)
    stderr = finished(process, MARGIN)
    took = time.monotonic() - sent
    print(f"sweep-signal: exit {process.returncode} {took:.2f} s after SIGTERM: {stderr.strip()}")
    assert process.returncode == 6, process.returncode
    assert "sweep interrupted" in stderr, stderr
    with h5py.File(out, "r") as handle:
        status = handle["sweep/status"][()]
    assert list(status) == [0], f"the point inside which the stop came is not pending: {status}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    cases = {"stall-wall-time": stall_wall_time, "stall-signal": stall_signal,
             "benettin-wall-time": benettin_wall_time, "sweep-signal": sweep_signal}
    parser.add_argument("case", choices=sorted(cases))
    args = parser.parse_args()
    Path(args.workdir).mkdir(parents=True, exist_ok=True)
    cases[args.case](args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
