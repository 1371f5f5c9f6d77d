"""Writes the three rock trend campaigns of issue 37 part 5 (examples/rock-*.json).
The floor arm: each preset written out with ε_f,min = 0.01 (the HJC concrete floor,
notebook/rock/jh2-damage-constants.md), every other constant as crates/grit-sph/src/rock.rs.
Usage: python3 notebook/rock/make_specs.py"""
import json


def rock(name, k1, k2, k3, rho, g, cp, hel, p_hel, t, ef_min):
    e = 9.0 * k1 * g / (3.0 * k1 + g)
    nu = (3.0 * k1 - 2.0 * g) / (2.0 * (3.0 * k1 + g))
    return {
        "name": name, "density_kg_m3": rho, "youngs_modulus_pa": e, "poisson_ratio": nu,
        "heat_capacity_j_kgk": cp,
        "plasticity": {"a": 1.01, "n": 0.76, "b": 0.68, "m": 0.83, "c": 0.005,
                       "ref_strain_rate_s": 1.0, "sfmax": 1.0, "hel_pa": hel,
                       "p_hel_pa": p_hel, "t_pa": t},
        "damage": {"d1": 0.005, "d2": 0.7, "ef_min": ef_min},
        "eos": {"kind": "polynomial", "rho0_kg_m3": rho, "k1_pa": k1, "k2_pa": k2,
                "k3_pa": k3, "beta": 1.0},
    }


ks = 16e9 / 1.5
sand_floor = rock("sandstone, ef_min 0.01", ks, ks * (-4.5 / 25.7), ks * (3.0 / 25.7), 2400.0,
                  6.4e9, 920.0, 1.11e9, 0.617e9, 4e6, 0.01)
gran_floor = rock("granite, ef_min 0.01", 25.7e9, -4.5e9, 3.0e9, 2660.0, 21.9e9, 790.0, 4.5e9,
                  2.93e9, 12e6, 0.01)
common = {"scene": "jet", "seed": 37, "samples": 3, "slice_ms": 0.005, "spacing_m": 1e-4,
          "target_depth_m": 4e-3}
specs = {
    "rock-trends": dict(common, name="rock-trends: sandstone and granite at 313, 343 and 370 m/s "
                        "(the AWJ paper's Figs. 25-26), presets and a 0.01 failure-strain floor, "
                        "0.04 kg/s, 0.1 ms (issue 37 part 5, reduced scene)",
                        material=["sandstone", "granite", sand_floor, gran_floor],
                        velocity_m_s=[313, 343, 370], mass_flow_kg_s=0.04, time_ms=0.1),
    "rock-massflow": dict(common, name="rock-massflow: sandstone at 350 m/s, M from 0.02 to "
                          "0.06 kg/s (the AWJ paper's Figs. 27-28), 0.1 ms (issue 37 part 5)",
                          material="sandstone", velocity_m_s=350,
                          mass_flow_kg_s=[0.02, 0.03, 0.04, 0.05, 0.055, 0.06], time_ms=0.1),
    "rock-400": dict(common, name="rock-400: sandstone at 400 m/s, 0.04 kg/s, 0.6 ms: cracks "
                     "against time, the water hammer before the first grain, the linear stage "
                     "(the AWJ paper's Figs. 22-23; issue 37 part 5)",
                     material="sandstone", velocity_m_s=400, mass_flow_kg_s=0.04, time_ms=0.6),
}
for stem, spec in specs.items():
    with open(f"examples/{stem}.json", "w") as f:
        json.dump(spec, f, indent=2)
        f.write("\n")
