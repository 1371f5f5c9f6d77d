#!/bin/bash
for r in 1 2 3 4; do
  for b in c540121 lto-exp; do
    pkill -STOP -f "grit-c540121 run"; sleep 1
    /work/bins/grit-$b bench impact --threads 1 --repeat 1 --json > /tmp/ab2-$b-$r.json 2>/dev/null
    pkill -CONT -f "grit-c540121 run"
    python3 -c "import json;d=json.load(open('/tmp/ab2-$b-$r.json'));print($r,'$b',{k:v for k,v in d.items() if isinstance(v,(int,float))})"
    sleep 10
  done
done
