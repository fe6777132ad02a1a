#!/usr/bin/env python3
"""The brake's periodic-orbit search ends on a stop request and at
max_wall_time inside its Newton steps, as a run does: the case is rate and
state at the law's defaults on the 2 mm/s belt, whose orbit Newton does not
find (docs/laws.md), with as many Newton steps as it likes.

  orbit-wall-time   &integrator max_wall_time = 3 s: exit 4 within the
                    limit and a margin after the run, the message names the
                    orbit's search and max_wall_time, no file written
  orbit-signal      the same without a limit, SIGTERM once the search has
                    begun: exit 6 within the margin, the message names the
                    orbit's search, an existing output file untouched

    brake_orbit_guard.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import signal
import subprocess
import time
from pathlib import Path

from machine_cases import case_main
from machine_guard import MARGIN, catches_sigterm, finished

from brake_law_oracles import CREEP_NML

# The creep case's input, run to 300 tau, with only the orbit's search on (an override file).
SLOW_NML = """&brake
  t_end = 300.0
/
&analysis
  spectrum = .false.
  poincare = .false.
  lyapunov = .false.
  lyapunov_spectrum = .false.
  rosenstein = .false.
  orbit = .true.
  orbit_transient = 190.0
  orbit_max_iterations = 1000
/
"""


def command(args, out, extra):
    creep = Path(args.workdir) / "creep.nml"
    creep.write_text(CREEP_NML)
    path = Path(args.workdir) / "slow_orbit.nml"
    path.write_text(SLOW_NML)
    return [args.binary, "-o", str(out), str(creep), str(path)] + extra


def run_alone(args):
    """Seconds the run takes without the orbit (the limit counts from the analysis's start)."""
    out = Path(args.workdir) / "run.h5"
    start = time.monotonic()
    subprocess.run(command(args, out, ["--quiet", "--force", "--set", "analysis.orbit=.false."]), check=True)
    return time.monotonic() - start


def orbit_wall_time(args):
    out = Path(args.workdir) / "limited.h5"
    out.unlink(missing_ok=True)
    alone = run_alone(args)
    limit = 3.0
    start = time.monotonic()
    process = subprocess.Popen(command(args, out, ["--quiet", "--set", f"integrator.max_wall_time={limit}"]),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # The run itself may take up to the limit too (it is bounded from its own start), then the search.
    stderr = finished(process, alone + limit + MARGIN)
    took = time.monotonic() - start
    print(f"orbit-wall-time: run alone {alone:.2f} s; exit {process.returncode} after {took:.2f} s: "
          f"{stderr.strip()}")
    assert process.returncode == 4, process.returncode
    assert "periodic orbit's search" in stderr and f"max_wall_time = {limit:g}" in stderr, stderr
    assert not out.exists(), "a file was written"


def orbit_signal(args):
    out = Path(args.workdir) / "kept.h5"
    out.write_bytes(b"an existing file the stopped search must leave as it was\n")
    before = out.read_bytes()
    alone = run_alone(args)
    process = subprocess.Popen(command(args, out, ["--quiet", "--force"]), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not catches_sigterm(process.pid) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    # Past the run (measured alone, twice that and a second for a loaded machine): in the search.
    time.sleep(2 * alone + 1.0)
    assert process.poll() is None, "the search ended by itself"
    sent = time.monotonic()
    process.send_signal(signal.SIGTERM)
    stderr = finished(process, MARGIN)
    took = time.monotonic() - sent
    print(f"orbit-signal: run alone {alone:.2f} s; exit {process.returncode} {took:.2f} s after SIGTERM: "
          f"{stderr.strip()}")
    assert process.returncode == 6, process.returncode
    assert "periodic orbit's search stopped on request" in stderr, stderr
    assert out.read_bytes() == before, "the existing file was changed"


if __name__ == "__main__":
    raise SystemExit(case_main(__doc__, {"orbit-wall-time": orbit_wall_time, "orbit-signal": orbit_signal}))
