import json, glob, statistics as st, sys, os
d = sys.argv[1] if len(sys.argv) > 1 else '/work/runs/bench-table'
order = ["0-base","1-fold-rates","2-pair-quotients","3-volumes-once","4-ref-distance-flag","5-u32-pairs",
         "6-same-body-lists","7-counting-sort","8-contact-bbox","campaign","s10-retry","simd"]
rows = []
prev = None
print("| binary | rounds | steps | wall 2 thr (s) median [min–max] | wall 1 thr (s) | M particle-steps/s/thread (2 thr) | 1-thread particle-steps/s vs previous | speed-up 1→2 | kernel sums | forces | neighbours | contact |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for b in order:
    fs = sorted(glob.glob(f"{d}/{b}-r*.json"))
    js = [json.load(open(f)) for f in fs if os.path.getsize(f) > 0]
    if not js: continue
    steps = js[0]["steps"]; n = js[0]["particles"]
    w2 = [j["wall_s"] for j in js]; w1 = [j["wall_1_thread_s"] for j in js]
    pst = st.median([j["particle_steps_per_s_per_thread"] for j in js]) / 1e6
    rate1 = n * steps / st.median(w1)
    rel = f"{rate1/prev:.2f}" if prev else ""
    prev = rate1
    sp = st.median([j["speedup_1_to_2"] for j in js])
    stg = lambda k: st.median([j["stages"].get(k, 0.0) + (j["stages"].get("rates", 0.0) if k == "kernel_sums" else 0.0) for j in js])
    print(f"| {b} | {len(js)} | {steps} | {st.median(w2):.2f} [{min(w2):.2f}–{max(w2):.2f}] | {st.median(w1):.2f} | {pst:.2f} | {rel} | {sp:.2f} | {stg('kernel_sums'):.2f} | {stg('forces'):.2f} | {stg('neighbours'):.3f} | {stg('contact'):.3f} |")
