#!/usr/bin/env python3
"""The seed bearing in ROSS's fluid-film engine against rotor-twin's film (issue 18).

Runs ROSS (PyPI `ross-rotordynamics`, its `PlainJournal` on the TEHD engine of
`ross/bearings/fluid_film/`) and `rotor-twin bearing --json` on the same bearing and prints the
comparison table. Not part of `cargo test` (ROSS is a Python install): make the venv with
tests/interop/setup-venv-ross.sh, then

    tests/.venv-ross/bin/python tests/interop/ross_plain_journal.py \
        [--binary target/release/rotor-twin] [--write-reference tests/reference/ross_plain_journal.csv]

--write-reference stores ROSS's figures (the version and inputs in the header);
tests/film_ross_plain_journal.rs asserts our film against them.

Inputs (both codes): the seed bearing of config/orc_microturbine_100kw.yaml, D 0.060 m, L 0.030 m,
radial clearance 40 µm, MDM ρ 900 kg/m³, µ 0.8 mPa·s at the 40 °C supply, c_p 1,820 J/(kg·K),
static load 275 N, zero gauge supply pressure. ROSS's frame (x horizontal, y up, load along -y,
rotation from +x to +y) is turned into ours (x along the load, y 90° ahead of it in the
direction of rotation): x_ours = -y_ross, y_ours = x_ross, so K_ours = [[kyy, -kyx], [-kxy, kxx]]
(ROSS's k_ij = -dF_i/dx_j, as its Lund & Thomsen test reads them).

Geometries:
  two_axial: ROSS PlainJournal(n_pads=2, pad_arc=160°): lands centred at 90° and 270° (ROSS), so
    two 20° grooves on the split line 90° either side of the load; ours
    `--grooves two-axial --groove-width-deg 20 --grid 144x16` (2.5°: the groove edges on nodes).
  plain: one 360° land (ROSS FixedGeometryBearing, of which PlainJournal is a translation; its
    PlainJournal(n_pads=1) fixes the edge at ROSS 0°), its two edges meeting at 216° after the
    load in the direction of rotation, where our film re-forms at 9,000 rpm (film_start_deg
    215.8) and where our thermal film takes in its fresh oil (E3): ROSS feeds a land at its
    edge. ε, φ, K, C do not depend on that edge (inside the cavitated arc; 0.4906-0.4908 for
    edges at 90°, 142°, 200°, 216° after the load), ROSS's power loss and temperatures do (its
    cavitated-arc shear and its groove mixing): `--plain-edge-deg`. Ours the plain 360° bearing,
    `--grid 120x20`.
ROSS mesh: total_ex_film 80 (a land), total_ez_film 20 (the length), total_ey_film 10.
Turbulence: ROSS off = re_laminar 1e12 (its flow-regime switch never fires), on = its defaults
(laminar below a land's largest local Re 500, fully turbulent above 1,000, Reichardt eddy
viscosity, δ 8.8, κ 0.4); ours `--flow laminar | turbulent | auto`.
Thermal: ROSS thermal_type "adiabatic" (its 2-D film energy equation, hot-oil carry-over 0.8,
ample flooded supply 1e-2 m³/s, liquid conductivity 0.1 W/(m·K) assumed), turbulence off; ours
`--thermal --supply-temperature-c 40 --specific-heat-j-per-kg-k 1820` (MDM's table). ROSS's
viscosity law is exponential, µ = µ1 exp(β (T - T1)); it is put through two points of our
table, (40 °C, 0.800 mPa·s) and (50 °C, 0.712838 mPa·s); the script prints its largest
distance from our table between 40 and 50 °C (0.075 %).
"""

import argparse
import io
import contextlib
import json
import math
import os
import subprocess
import sys
import warnings

import numpy as np

D, L, C, RHO, MU, CP, LOAD = 0.060, 0.030, 40e-6, 900.0, 0.8e-3, 1820.0, 275.0
T_SUPPLY_C = 40.0
# ROSS's exponential law through two points of the machine file's MDM table
LAW_POINTS = ((40.0, 0.800000e-3), (50.0, 0.712838e-3))
CONDUCTIVITY = 0.1  # W/(m·K), MDM liquid, assumed (only ROSS's energy equation uses it)
ROSS_MESH = dict(total_ex_film=80, total_ez_film=20, total_ey_film=10, total_ey_pad=10)
OUR_GRID = {"two_axial": "144x16", "plain": "120x20"}
# the plain land's edge, degrees after the load in the direction of rotation (see above)
PLAIN_EDGE_DEG = 216.0

# (case, geometry, speed rpm, ROSS turbulence on, thermal)
CASES = (
    [("isothermal", "two_axial", n, False, False) for n in (6000, 8000, 9000)]
    + [("isothermal", "plain", n, False, False) for n in (6000, 8000, 9000)]
    + [("turbulence", g, n, True, False) for g in ("two_axial", "plain") for n in (9000, 18000)]
    + [("isothermal", g, 18000, False, False) for g in ("two_axial", "plain")]
    + [("thermal", "plain", n, False, True) for n in (6000, 9000)]
)

COLUMNS = (
    "lands,speed_rpm,turbulence,thermal,eps,attitude_deg,power_loss_w,p_max_pa,"
    "kxx,kxy,kyx,kyy,cxx,cxy,cyx,cyy,kxx_fd,kxy_fd,kyx_fd,kyy_fd,t_inlet_c,t_max_c,t_outlet_c,"
    "re_max"
).split(",")
LANDS = {"two_axial": 2, "plain": 1}
# central-difference step of the stiffness check, fraction of the clearance
FD_STEP = 0.005


def lubricant():
    (t1, mu1), (t2, mu2) = LAW_POINTS
    return {
        "liquid_viscosity1": mu1,
        "temperature1": t1 + 273.15,
        "liquid_viscosity2": mu2,
        "temperature2": t2 + 273.15,
        "liquid_density": RHO,
        "liquid_specific_heat": CP,
        "liquid_thermal_conductivity": CONDUCTIVITY,
    }


def ross_bearing(geometry, rpm, turbulence, thermal, plain_edge_deg, **extra):
    """One ROSS solve (a PlainJournal or one 360° FixedGeometryBearing land)."""
    from ross.bearings.fixed_geometry import FixedGeometryBearing
    from ross.bearings.plain_journal import PlainJournal
    from ross.units import Q_

    regime = dict(re_laminar=500, re_turbulent=1000) if turbulence else dict(
        re_laminar=1e12, re_turbulent=2e12
    )
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        common = dict(
            n=0,
            journal_diameter=D,
            radial_clearance=C,
            pad_thickness=D / 4.0,
            oil_supply_temperature=Q_(T_SUPPLY_C, "degC"),
            reference_temperature=Q_(T_SUPPLY_C, "degC"),
            speed=Q_([rpm], "RPM"),
            fxs_load=0.0,
            fys_load=-LOAD,
            lubricant=lubricant(),
            oil_flow_v=1e-2,
            thermal_type="adiabatic" if thermal else None,
            **ROSS_MESH,
            **regime,
            **extra,
        )
        common.setdefault("initial_position", (0.1, -0.1))
        if geometry == "two_axial":
            b = PlainJournal(pad_axial_length=L, n_pads=2, pad_arc=Q_(160.0, "deg"), **common)
        else:
            # the load is at ROSS 270°, rotation towards +y: our angle a is ROSS 270° + a; the
            # land's centre is opposite its edges
            centre = (270.0 + plain_edge_deg + 180.0) % 360.0
            b = FixedGeometryBearing(
                pivot_angle=Q_([centre], "deg"), pad_arc=Q_([360.0], "deg"),
                pad_axial_length=[L], preload=[0.0], offset=[0.5], **common)
    return b._results.outputs[0]


def ross_fd_stiffness(geometry, rpm, turbulence, plain_edge_deg, x0, y0):
    """K of ROSS's own film force by central differences (±FD_STEP c, the journal held:
    equilibrium_type match_eccentricity), in ROSS's frame, k_ij = -dF_i/dx_j."""
    def force(x, y):
        o = ross_bearing(geometry, rpm, turbulence, False, plain_edge_deg,
                         equilibrium_type="match_eccentricity", initial_position=(x, y))
        return np.array([o["fx_hydro"][0], o["fy_hydro"][0]])

    h = FD_STEP
    dfx = (force(x0 + h, y0) - force(x0 - h, y0)) / (2 * h * C)
    dfy = (force(x0, y0 + h) - force(x0, y0 - h)) / (2 * h * C)
    return dict(kxx=-dfx[0], kyx=-dfx[1], kxy=-dfy[0], kyy=-dfy[1])


def ross_case(geometry, rpm, turbulence, thermal, plain_edge_deg=PLAIN_EDGE_DEG):
    """One ROSS solve; the figures in our frame (and, isothermal, the stiffness of its own
    force by central differences)."""
    o = ross_bearing(geometry, rpm, turbulence, thermal, plain_edge_deg)
    xr, yr = o["xj_cb"][0], o["yj_cb"][0]
    xo, yo = -yr, xr
    k = lambda name: float(o[name][0])  # noqa: E731
    row = dict(
        eps=math.hypot(xo, yo),
        attitude_deg=math.degrees(math.atan2(yo, xo)),
        power_loss_w=float(o["power_loss"][0]),
        p_max_pa=float(o["y_max_p"][0]),
        kxx=k("kyy"), kxy=-k("kyx"), kyx=-k("kxy"), kyy=k("kxx"),
        cxx=k("cyy"), cxy=-k("cyx"), cyx=-k("cxy"), cyy=k("cxx"),
        re_max=max(o["dhc_re_max"][0]),
    )
    # the film force it ends with, against the load (its load-matching loop's residual)
    row["load_residual"] = math.hypot(o["fx_hydro"][0], o["fy_hydro"][0] - LOAD) / LOAD
    if not (thermal or turbulence):
        # not with turbulence: ROSS's turbulent force re-solved with the journal held at its own
        # equilibrium (match_eccentricity) is 354 N, not 275 N (two_axial, 9,000 rpm): its two
        # modes do not end at the same eddy-viscosity state, so differences of it are no check
        fd = ross_fd_stiffness(geometry, rpm, turbulence, plain_edge_deg, xr, yr)
        row.update(kxx_fd=fd["kyy"], kxy_fd=-fd["kyx"], kyx_fd=-fd["kxy"], kyy_fd=fd["kxx"])
    if thermal:
        # the loaded land's inlet (after mixing) and outlet bulk temperatures, the film's peak
        row.update(
            t_inlet_c=float(np.ravel(o["temp_in_let"][0])[0]) - 273.15,
            t_max_c=float(o["y_max_t"][0]) - 273.15,
            t_outlet_c=float(np.ravel(o["temp_out_let_bulk"][0])[0]) - 273.15,
        )
    return row


def ours(binary, geometry, rpm, flow, thermal):
    args = [
        binary, "bearing", "--json", "--speed-rpm", str(rpm), "--load-n", str(LOAD),
        "--diameter-m", str(D), "--length-m", str(L), "--clearance-m", str(C),
        "--viscosity-pa-s", str(MU), "--density-kg-m3", str(RHO),
        "--grid", OUR_GRID[geometry], "--flow", flow,
    ]
    if geometry == "two_axial":
        args += ["--grooves", "two-axial", "--groove-width-deg", "20"]
    if thermal:
        args += ["--thermal", "--supply-temperature-c", str(T_SUPPLY_C),
                 "--specific-heat-j-per-kg-k", str(CP)]
    d = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)
    (kxx, kxy), (kyx, kyy) = d["stiffness_n_per_m"]
    (cxx, cxy), (cyx, cyy) = d["damping_n_s_per_m"]
    row = dict(
        eps=d["eccentricity_ratio"], attitude_deg=d["attitude_angle_deg"],
        power_loss_w=d["power_loss_w"], p_max_pa=d["max_pressure_pa"],
        kxx=kxx, kxy=kxy, kyx=kyx, kyy=kyy, cxx=cxx, cxy=cxy, cyx=cyx, cyy=cyy,
        re_max=d["film_reynolds_number"],
    )
    if thermal:
        t = d["thermal"]
        row.update(t_inlet_c=t["inlet_temperature_c"], t_max_c=t["max_temperature_c"],
                   t_outlet_c=t["rupture_temperature_c"])
    return row


def fmt(r):
    k = [r[n] / 1e6 for n in ("kxx", "kxy", "kyx", "kyy")]
    c = [r[n] / 1e3 for n in ("cxx", "cxy", "cyx", "cyy")]
    s = (f"ε {r['eps']:.4f}  φ {r['attitude_deg']:6.2f}°  P {r['power_loss_w']:7.1f} W  "
         f"p_max {r['p_max_pa'] / 1e6:.3f} MPa  K [{', '.join(f'{x:6.2f}' for x in k)}] MN/m  "
         f"C [{', '.join(f'{x:5.1f}' for x in c)}] kN·s/m")
    if "t_max_c" in r:
        s += f"  T in {r['t_inlet_c']:.1f} max {r['t_max_c']:.1f} out {r['t_outlet_c']:.1f} °C"
    return s


# the machine file's MDM table (config/orc_microturbine_100kw.yaml), °C and Pa·s
TABLE_C = (10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0, 110.0, 120.0)
TABLE_PA_S = (1.16888e-3, 1.02439e-3, 0.903011e-3, 0.800000e-3, 0.712838e-3, 0.639124e-3,
              0.575962e-3, 0.520959e-3, 0.472895e-3, 0.431143e-3, 0.394765e-3, 0.362473e-3)


def law_check():
    """Largest distance of ROSS's exponential law from our table, 40-50 °C (the film's range).
    Ours interpolates ln µ against -1/T by Moler's pchip (src/film/viscosity.rs), which is
    scipy's PchipInterpolator (inside the table; the end slopes differ, not used here)."""
    from scipy.interpolate import PchipInterpolator

    (t1, mu1), (t2, mu2) = LAW_POINTS
    beta = math.log(mu2 / mu1) / (t2 - t1)
    x = -1.0 / (np.array(TABLE_C) + 273.15)
    table = PchipInterpolator(x, np.log(TABLE_PA_S))
    t = np.linspace(t1, t2, 101)
    ours = np.exp(table(-1.0 / (t + 273.15)))
    exp_law = mu1 * np.exp(beta * (t - t1))
    return beta, float(np.max(np.abs(exp_law / ours - 1.0)))


def quiet_import_ross():
    """`import ross`, its dependencies' REFPROP notice (printed by CoolProp's C library on
    stdout at import) sent to /dev/null."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        import ross
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(devnull)
        os.close(saved)
    return ross


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default="target/release/rotor-twin")
    ap.add_argument("--write-reference")
    ap.add_argument("--plain-edge-deg", type=float, default=PLAIN_EDGE_DEG,
                    help="the plain land's edge, degrees after the load in rotation")
    a = ap.parse_args()
    if a.write_reference and a.plain_edge_deg != PLAIN_EDGE_DEG:
        sys.exit("--write-reference stores the default --plain-edge-deg only")
    ross = quiet_import_ross()

    beta, worst = law_check()
    print(f"ROSS {ross.__version__}; exponential law β = {beta:.6f} 1/K through "
          f"{LAW_POINTS}; |exp/table - 1| ≤ {worst * 100:.3f} % on 40-50 °C")
    rows = []
    for case, geometry, rpm, turbulence, thermal in CASES:
        r = ross_case(geometry, rpm, turbulence, thermal, a.plain_edge_deg)
        rows.append((case, geometry, rpm, turbulence, thermal, r))
        flows = ["turbulent", "auto"] if turbulence else ["laminar"]
        print(f"\n{case} {geometry} {rpm} rpm"
              f"{' (ROSS turbulence on)' if turbulence else ''}{' thermal' if thermal else ''}")
        print(f"  ROSS            {fmt(r)}  Re_max {r['re_max']:.0f}  "
              f"|F - W|/W {r['load_residual']:.1e}")
        if "kxx_fd" in r:
            kfd = ", ".join(f"{r[n] / 1e6:6.2f}" for n in ("kxx_fd", "kxy_fd", "kyx_fd", "kyy_fd"))
            print(f"  ROSS K by central differences of its force [{kfd}] MN/m")
        for flow in flows:
            print(f"  ours {flow:10s} {fmt(ours(a.binary, geometry, rpm, flow, thermal))}")
    if a.write_reference:
        write_reference(a.write_reference, ross.__version__, beta, rows)


def write_reference(path, version, beta, rows):
    with open(path, "w") as f:
        f.write(
            f"# ROSS {version} (PyPI ross-rotordynamics), ross.bearings.plain_journal.PlainJournal "
            "on its fluid-film TEHD engine; written by tests/interop/ross_plain_journal.py.\n"
            f"# Inputs: D {D} m, L {L} m, radial clearance {C} m, load {LOAD} N along -y (ROSS), "
            f"rho {RHO} kg/m3, mu {MU} Pa s at the {T_SUPPLY_C} C supply, c_p {CP} J/(kg K), "
            f"conductivity {CONDUCTIVITY} W/(m K), supply pressure 0, flooded 1e-2 m3/s.\n"
            "# two_axial: n_pads 2, pad_arc 160 deg (20 deg grooves 90 deg either side of the "
            "load); plain: FixedGeometryBearing, one 360 deg land, its edges "
            f"{PLAIN_EDGE_DEG} deg after the load in rotation.\n"
            f"# Mesh {ROSS_MESH}. turbulence 0: re_laminar 1e12 (off); 1: re_laminar 500, "
            "re_turbulent 1000 (its defaults). thermal 1: thermal_type adiabatic, exponential "
            f"law through {LAW_POINTS} (beta {beta:.6f} 1/K); 0: isoviscous.\n"
            "# lands: 2 two_axial, 1 plain. Our frame: x along the load, y 90 deg ahead in "
            "rotation; eps, attitude_deg, power_loss_w (W), p_max_pa, K (N/m) and C (N s/m) as "
            "ROSS reports them, K_fd (N/m) central differences of ROSS's own film force "
            f"(+-{FD_STEP} c, journal held), temperatures (C; inlet after mixing, film peak, "
            "outlet bulk of the land), re_max (largest local Re); nan: not computed.\n"
        )
        f.write(",".join(COLUMNS) + "\n")
        for case, geometry, rpm, turbulence, thermal, r in rows:
            vals = [str(LANDS[geometry]), str(rpm), str(int(turbulence)), str(int(thermal))]
            for name in COLUMNS[4:]:
                vals.append(f"{r[name]:.6g}" if name in r else "nan")
            f.write(",".join(vals) + "\n")
    print(f"\nwrote {path}")


if __name__ == "__main__":
    sys.exit(main())
