"""MDM (octamethyltrisiloxane, CAS 107-51-7) liquid properties for the built-in microturbine's
viscosity-temperature law (issue 12; README, "Oil supply temperature").

Sources, as evaluated by this script (pip install CoolProp==8.0.0 thermo==0.6.1):
- dynamic viscosity: REFPROP 10.0's MDM viscosity model (NIST; Huber, NISTIR 8209, 2018), through
  the `thermo` library's fit to REFPROP (`ViscosityLiquid` method REFPROP_FIT);
- density and isobaric heat capacity: the multiparameter equation of state of Colonna, Nannan and
  Guardone, Fluid Phase Equilibria 263 (2008) 115-130, through CoolProp 8.0.0 ("MDM"), at 5 bar.
Cross-check: the 1 mm^2/s grade of dimethylsiloxane fluid is MDM; REFPROP gives 1.020 mm^2/s at 25 C.

Writes mdm_viscosity.csv (T in C, mu in Pa s, rho in kg/m^3, nu in mm^2/s, cp in J/(kg K)) and
prints the Walther slope B (ASTM D341-09) fitted by least squares over 10-120 C to the law's
own variable: the twin's law takes its density constant (mu = rho nu, rho = 900 kg/m^3, the seed's), so
its nu is mu / 900 and must follow MDM's DYNAMIC viscosity ratio mu(T)/mu(40 C), anchored at the
seed's 0.8 mPa s at 40 C (0.889 mm^2/s); prints the law's 80 C point.
"""
import math
import os

import CoolProp.CoolProp as CP
from thermo import Chemical

TEMPERATURES_C = [10, 20, 25, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120]
P_PA = 5e5


def d341_z(nu):
    return nu + 0.7 + math.exp(-1.47 - 1.84 * nu - 0.51 * nu * nu)


def loglog(nu):
    return math.log10(math.log10(d341_z(nu)))


def d341_nu(z):
    w = z - 0.7
    return w - math.exp(-0.7487 - 3.295 * w + 0.6119 * w * w - 0.3193 * w**3)


def main():
    liquid = Chemical("octamethyltrisiloxane", T=313.15, P=P_PA).ViscosityLiquid
    rows = []
    for t in TEMPERATURES_C:
        tk = t + 273.15
        mu = liquid.calculate(tk, "REFPROP_FIT")
        rho = CP.PropsSI("D", "T", tk, "P", P_PA, "MDM")
        cp = CP.PropsSI("C", "T", tk, "P", P_PA, "MDM")
        rows.append((t, mu, rho, mu / rho * 1e6, cp))
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "mdm_viscosity.csv"), "w") as f:
        f.write("# MDM liquid at 5 bar: mu REFPROP 10 (via thermo REFPROP_FIT); rho, cp Colonna et al. 2008 EOS (via CoolProp 8.0.0); mdm_viscosity.py\n")
        f.write("temperature_c,viscosity_pa_s,density_kg_m3,kinematic_viscosity_mm2_s,specific_heat_j_per_kg_k\n")
        for t, mu, rho, nu, cp in rows:
            f.write(f"{t},{mu:.6e},{rho:.2f},{nu:.5f},{cp:.1f}\n")
    xs = [math.log10(t + 273.15) for t, *_ in rows]
    mu40 = next(mu for t, mu, *_ in rows if t == 40)
    nu40 = 0.8e-3 / 900.0 * 1e6
    ys = [loglog(nu40 * mu / mu40) for _, mu, *_ in rows]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    b = -sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    y80 = loglog(nu40) - b * (math.log10(353.15) - math.log10(313.15))
    nu80 = d341_nu(10 ** (10**y80))
    print(f"Walther B (least squares, 10-120 C): {b:.4f}")
    print(f"law anchored at {nu40:.4f} mm^2/s at 40 C: {nu80:.4f} mm^2/s at 80 C")
    for t, mu, rho, nu, cp in rows:
        print(f"{t:5.0f} C  mu {mu*1e3:.4f} mPa s  rho {rho:.1f}  nu {nu:.4f}  cp {cp:.0f}")


if __name__ == "__main__":
    main()
