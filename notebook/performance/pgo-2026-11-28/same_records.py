"""Compare a resumed sample's impact records with those a campaign database stored.

usage: same_records.py OUT_JSON DB CELL SAMPLE FIRST LAST
Prints each impact's verdict; exits 1 if any record differs from the stored one.
"""
import json
import sqlite3
import sys

out, db, cell, sample, first, last = sys.argv[1:7]
cell, sample, first, last = int(cell), int(sample), int(first), int(last)
mine = {r["impact"]: r for r in json.load(open(out))["impacts"]}
con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
rows = con.execute(
    "select u.unit, u.record from units u join jobs j on j.id = u.job_id "
    "where j.cell_index = ? and j.sample_index = ? and u.unit between ? and ?",
    (cell, sample, first, last),
).fetchall()
bad = 0
for unit, rec in sorted(rows):
    same = json.loads(rec) == mine.get(unit)
    bad += not same
    print(f"impact {unit}: {'same' if same else 'DIFFERENT'}")
if len(rows) != last - first + 1:
    print(f"only {len(rows)} stored records in {first}..{last}")
    bad += 1
sys.exit(1 if bad else 0)
