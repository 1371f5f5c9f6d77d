"""Reopen a finished cell of a farm campaign for `step` more impacts per sample, with each
sample's latest kept checkpoint (run with no grit process on the database)."""
import glob, hashlib, re, sqlite3, sys, time
db, keep, cell, to = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
c = sqlite3.connect(db)
now = int(time.time() * 1000)
jobs = c.execute("select id, sample_index, units_planned, units_done, state from jobs where cell_index=?", (cell,)).fetchall()
old = {p for (_, _, p, _, _) in jobs}
assert len(old) == 1, old
old = old.pop()
assert all(st == 'done' for *_, st in jobs), "cell still running"
for jid, s, planned, done, st in jobs:
    files = sorted(glob.glob(f"{keep}/c{cell}-{s}-*.ckpt"), key=lambda f: int(re.search(r"-(\d+)\.ckpt$", f).group(1)))
    f = files[-1]
    n = int(re.search(r"-(\d+)\.ckpt$", f).group(1))
    data = open(f, 'rb').read()
    c.execute("insert or replace into checkpoints(job_id, units_done, data, updated_ms, sha256) values (?,?,?,?,?)",
              (jid, n, data, now, hashlib.sha256(data).hexdigest()))
    print(f"sample {s}: job {jid}, checkpoint at {n} of {done} stored units")
c.execute("update jobs set units_planned=?, state='queued', lease_id=NULL, worker=NULL, lease_expires_ms=NULL, updated_ms=? where cell_index=?", (to, now, cell))
c.execute("update cells set units=? where cell_index=?", (to, cell))
c.execute("update campaigns set units_total = units_total + ?", ((to - old) * len(jobs),))
c.commit()
print(f"cell {cell}: {len(jobs)} jobs from {old} to {to} impacts")
