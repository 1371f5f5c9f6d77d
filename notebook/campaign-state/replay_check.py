"""Replays stored campaign impacts with another binary and compares them with the database's
records, field for field: the check that a binary which replaced a campaign's (a new build, a
patch that should keep the bits) computes what the campaign stored.

usage: replay_check.py BIN DB CELL SAMPLE N CKPT [IMPACTS]
  BIN      the binary to check (`grit`)
  DB       the campaign's grit.db (opened read-only)
  CELL, SAMPLE  the job's cell and sample index
  N        the impacts done in the checkpoint CKPT (keep-fast.sh's cCELL-SAMPLE-N.ckpt)
  IMPACTS  how many impacts to replay from it (default 1)
Exit 0 when every replayed impact equals its stored record, 1 otherwise (2 when the database
does not hold them yet).
"""
import json
import sqlite3
import subprocess
import sys
import tempfile

binary, db, cell, sample, n, ckpt = sys.argv[1:7]
cell, sample, n = int(cell), int(sample), int(n)
count = int(sys.argv[7]) if len(sys.argv) > 7 else 1
con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
stored = {
    unit: json.loads(rec)
    for unit, rec in con.execute(
        "select u.unit, u.record from units u join jobs j on j.id = u.job_id "
        "where j.cell_index = ? and j.sample_index = ? and u.unit between ? and ?",
        (cell, sample, n + 1, n + count),
    )
}
missing = [u for u in range(n + 1, n + count + 1) if u not in stored]
if missing:
    print(f"replay_check: the database holds no record of impacts {missing} yet", file=sys.stderr)
    sys.exit(2)
with tempfile.NamedTemporaryFile(suffix=".json") as out:
    subprocess.run(
        [binary, "sample", "--resume", ckpt, "--impacts", str(n + count), "--threads", "1",
         "--json", "-o", out.name],
        check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )
    replayed = {r["impact"]: r for r in json.load(open(out.name))["impacts"]}
bad = 0
for unit in range(n + 1, n + count + 1):
    same = replayed.get(unit) == stored[unit]
    bad += not same
    o = stored[unit]["outcome"]
    print(f"cell {cell} sample {sample} impact {unit}: {'same' if same else 'DIFFERENT'} "
          f"(steps {o['steps']}, loss {o['mass_loss_kg']:.6e} kg, damage added "
          f"{o['damage_added_kg']:.6e} kg)")
    if not same:
        print(f"  stored   {json.dumps(stored[unit])}\n  replayed {json.dumps(replayed.get(unit))}")
sys.exit(1 if bad else 0)
