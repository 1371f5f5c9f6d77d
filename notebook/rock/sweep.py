"""Over-fracture sweep (issue 37 part 1): the pure water jet at 400 m/s on sandstone, with the
damage constants, the tensile limit or the target's size changed one at a time in a --scene
file; prints the fractured particles and cracks per slice.
Usage: python3 sweep.py OUTDIR NAME [key=value ...]  (keys: d1 d2 ef_min t_pa width depth
time_ms slice_ms mass_flow)."""
import json, subprocess, sys, os

G = os.environ.get("GRIT", "/work/target-d/release/grit")
out, name, kv = sys.argv[1], sys.argv[2], dict(a.split("=") for a in sys.argv[3:])
f = lambda k, d: float(kv.get(k, d))

# Red sandstone as crates/grit-sph/src/rock.rs writes it, with the same arithmetic.
k1 = 16e9 / 1.5
g = 6.4e9
e = 9.0 * k1 * g / (3.0 * k1 + g)
nu = (3.0 * k1 - 2.0 * g) / (2.0 * (3.0 * k1 + g))
mat = {
    "name": "sandstone", "density_kg_m3": 2400.0, "youngs_modulus_pa": e, "poisson_ratio": nu,
    "heat_capacity_j_kgk": 920.0,
    "plasticity": {"a": 1.01, "n": 0.76, "b": 0.68, "m": 0.83, "c": 0.005,
                   "ref_strain_rate_s": 1.0, "sfmax": 1.0, "hel_pa": 1.11e9,
                   "p_hel_pa": 0.617e9, "t_pa": f("t_pa", 4e6)},
    "damage": {"d1": f("d1", 0.005), "d2": f("d2", 0.7), "ef_min": f("ef_min", 0.0)},
    "eos": {"kind": "polynomial", "rho0_kg_m3": 2400.0, "k1_pa": k1,
            "k2_pa": k1 * (-4.5 / 25.7), "k3_pa": k1 * (3.0 / 25.7), "beta": 1.0},
}
scene = {"material": mat}
if "width" in kv: scene["target_width_m"] = f("width", 0)
if "depth" in kv: scene["target_depth_m"] = f("depth", 0)
if kv.get("preset"): scene = {}
os.makedirs(out, exist_ok=True)
sp = os.path.join(out, name + ".scene.json")
json.dump(scene, open(sp, "w"))
cmd = [G, "jet", "--scene", sp, "--velocity-m-s", kv.get("v", "400"),
       "--mass-flow-kg-s", kv.get("mass_flow", "0"), "--time-ms", kv.get("time_ms", "0.012"),
       "--slice-ms", kv.get("slice_ms", "0.0005"), "--spacing-m", "1e-4", "--seed", "1",
       "--threads", "1", "--json", "-o", os.path.join(out, name + ".json")]
if kv.get("preset"): cmd += ["--material", "sandstone"]
subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
d = json.load(open(os.path.join(out, name + ".json")))
n = sum(1 for _ in [0])
rows = [(round(s["t_s"] * 1e6, 2), s.get("fractured_particles"), s.get("crack_count"),
         round(s.get("mass_loss_kg_m", 0) * 1e3, 4)) for s in d["series"]]
print(name, " ".join(kv.get(k, "") for k in sorted(kv)), rows)
