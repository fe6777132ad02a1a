#!/usr/bin/env python3
"""A value left at its default, refused because of another variable the
input did set, is named at the line of the variable that was set
(docs/input.md, Checks): 'file:line: &group: name, with the default
&group: variable = value: reason'.  One case per check that compares a
default with a set value, in each scene's checks: the laws' and the
machine's (machine), the brake's (brake), the sweep's (sweep) and the
AFM's (afm).  Each input is refused with exit code 3 naming the file, the
line of the set variable, its group and name and the default's group and
name, and writes no file (machine_cases.check_refusals).

    default_partner_refusals.py --binary B --inputs DIR --workdir DIR machine|brake|sweep|afm
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_cases import check_refusals, case_main  # noqa: E402

# (The inputs begin with four lines: a comment and &job; the groups below start at line 5.)


def machine(args):
    """The laws' checks (on the machine) and the machine's continuation."""
    cases = [
        # F_s's default 1.5 N below the F_c set.
        ("&law\n  model = 'stribeck'\n  fc = 2.0\n/\n", 7,
         "&law: fc, with the default &law: fs = 1.50000: ", "must be >= fc = 2.00000"),
        # Coulomb's default mu_s = 0.4 below the mu set.
        ("&law\n  model = 'coulomb'\n  mu = 0.5\n/\n", 7,
         "&law: mu, with the default &law: mu_s = 0.400000: ", "must be >= mu = 0.500000"),
        # The default break-away deflection 5e-6 m above F_c/sigma0 = 1e-6 m with the sigma0 set.
        ("&law\n  model = 'elastoplastic'\n  sigma0 = 1.0e6\n/\n", 7,
         "&law: sigma0, with the default &law: z_ba = 5.000000E-6: ", "below fc/sigma0 = 1.000000E-6"),
        # Three elements take the first three default weights, which add up to 0.6.
        ("&law\n  model = 'gms'\n  elements = 3\n/\n", 7,
         "&law: elements, with the default &law: element_weight = ", "the 3 weights add up to 0.600000"),
        # A fifth element has no default stiffness.
        ("&law\n  model = 'gms'\n  elements = 5\n  element_weight = 0.2, 0.2, 0.2, 0.2, 0.2\n/\n", 7,
         "&law: elements, with the default &law: element_stiffness(5) = 0.00000: ", "each of the 5 elements"),
        # The tabulated law without its file.
        ("&law\n  model = 'table'\n/\n", 6, "&law: model, with the default &law: table_file = '': ",
         "needs a file"),
        # The continuation's default end 0 is a machine without mass.
        ("&law\n  model = 'lugre'\n/\n&analysis\n  orbit = .true.\n  section = 'w_zero_up'\n"
         "  continuation = 'mass'\n/\n", 11,
         "&analysis: continuation, with the default &analysis: continuation_end = 0.00000: ",
         "not a valid machine"),
        # The default section, the slip onsets, with a law that has none.
        ("&machine\n  t_end = 2000.0\n/\n&law\n  model = 'lugre'\n/\n&analysis\n  poincare = .true.\n/\n", 9,
         "&law: model, with the default &analysis: section = 'stick_to_slip': ", "has none"),
        # (The machine's default window and transients lie in its default run, so a switch alone is
        # no longer refused: machine_oracles.py's analysis-defaults runs each.)
        # A value that was itself set keeps its own line, the partner default or not.
        ("&law\n  model = 'stribeck'\n  fs = 0.5\n/\n", 7, "&law: fs = 0.500000: ", "must be >= fc = 1.00000"),
    ]
    check_refusals(args, cases, "machine")


def brake(args):
    """The brake's mu/mu_s, y0 (N' > 0), k2 = k1 and continuation checks."""
    cases = [
        ("&brake\n  mu_s = 0.5\n/\n", 6, "&brake: mu_s, with the default &brake: mu = 0.590000: ",
         "the switched model needs mu <= mu_s = 0.500000"),
        # y0 = 0 (default): N' = g_prime.
        ("&brake\n  g_prime = -0.01\n/\n", 6, "&brake: g_prime, with the default &brake: y0 = 0.00000: ",
         "the initial normal force N'"),
        # The same with units = 'dimensional': g_prime = g (m + m_c)/k1 = 0 without gravity.
        ("&brake\n  units = 'dimensional'\n/\n&brake_dimensional\n  gravity = 0.0\n/\n", 9,
         "&brake_dimensional: gravity, with the default &brake: y0 = 0.00000: ", "must be > 0"),
        ("&brake\n  units = 'dimensional'\n/\n&brake_dimensional\n  k1 = 300.0\n/\n", 9,
         "&brake_dimensional: k1, with the default &brake_dimensional: k2 = 214.620: ", "Eq. 10 assumes k2 = k1"),
        # The continuation's default end 0 is a brake with xi = 0.
        ("&brake\n  t_end = 100.0\n/\n&analysis\n  orbit = .true.\n  continuation = 'xi'\n/\n", 10,
         "&analysis: continuation, with the default &analysis: continuation_end = 0.00000: ",
         "not a valid brake"),
        # Both at their defaults cannot conflict; a set mu keeps its own line.
        ("&brake\n  mu = 0.7\n/\n", 6, "&brake: mu = 0.700000: ", "needs mu <= mu_s = 0.590000"),
    ]
    check_refusals(args, cases, "brake", scene="brake")


def sweep(args):
    """The sweep's values, count and logarithmic ends left at their defaults."""
    cases = [
        ("&sweep\n  sweep_variable = 'brake.mu'\n/\n", 6,
         "&sweep: sweep_variable, with the default &sweep: sweep_values = (none): ", "give at least one value"),
        ("&sweep\n  sweep_variable = 'brake.mu'\n  sweep_spacing = 'linear'\n/\n", 7,
         "&sweep: sweep_spacing, with the default &sweep: sweep_count = 0: ", "must be at least 1"),
        ("&sweep\n  sweep_variable = 'brake.v_dr_prime'\n  sweep_spacing = 'log'\n  sweep_to = 1e-3\n"
         "  sweep_count = 3\n/\n", 7, "&sweep: sweep_spacing, with the default &sweep: sweep_from = 0.00000: ",
         "must not be 0 for sweep_spacing = 'log'"),
        ("&sweep\n  sweep_variable = 'brake.v_dr_prime'\n  sweep_spacing = 'log'\n  sweep_from = -4e-3\n"
         "  sweep_count = 3\n/\n", 8, "&sweep: sweep_from, with the default &sweep: sweep_to = 0.00000: ",
         "must be nonzero and of the sign of sweep_from"),
        # The second axis names its own variables.
        ("&sweep\n  sweep_variable = 'brake.mu'\n  sweep_values = 0.5\n  sweep_variable2 = 'brake.xi'\n"
         "  sweep_spacing2 = 'linear'\n/\n", 9,
         "&sweep: sweep_spacing2, with the default &sweep: sweep_count2 = 0: ", "must be at least 1"),
    ]
    check_refusals(args, cases, "sweep", scene="brake")


def afm(args):
    """The AFM's dampers, map size, surfaces and nets."""
    cases = [
        # cz (default 0) divides in the overdamped tip over the lattice sum.
        ("&surface\n  potential = 'lj'\n/\n&tip\n  model = 'overdamped'\n/\n", 9,
         "&tip: model, with the default &tip: cz = 0.00000: ", "for model = 'overdamped'"),
        # ... and is the heat bath's damper in z at a temperature.
        ("&surface\n  potential = 'lj'\n/\n&thermal\n  temperature = 300.0\n/\n", 9,
         "&thermal: temperature, with the default &tip: cz = 0.00000: ", "heat bath"),
        # The default damping 1e-3 N s/m is too weak for Kramers' rate on a heavy tip.
        ("&tip\n  mass = 1.0e-6\n/\n&thermal\n  temperature = 300.0\n  model = 'kramers'\n/\n", 6,
         "&tip: mass, with the default &tip: cx = 1.000000E-3: ", "energy diffusion"),
        ("&scan\n  ny = 20000000\n/\n", 6, "&scan: ny, with the default &scan: nx = 128: ",
         "more than 2147483647 per dataset"),
        ("&surface\n  potential = 'fourier'\n/\n", 6, "&surface: potential, with the default &fourier: cosine = 0.0: ",
         "every coefficient of &fourier is 0"),
        ("&surface\n  potential = 'lj'\n  net = 'file'\n/\n", 7,
         "&surface: net, with the default &surface: net_file = '': ", "name an XYZ file"),
        ("&surface\n  potential = 'lj'\n  substitutions = 3\n/\n", 7,
         "&surface: substitutions, with the default &surface: substitution_species = '': ", "not in the species"),
        ("&surface\n  potential = 'lj'\n  species = 'C', 'Si'\n/\n", 7,
         "&surface: species, with the default &surface: sigma(2) = 0.00000: ", "for species Si"),
    ]
    check_refusals(args, cases, "afm", scene="afm")


if __name__ == "__main__":
    sys.exit(case_main(__doc__, {"machine": machine, "brake": brake, "sweep": sweep, "afm": afm}))
