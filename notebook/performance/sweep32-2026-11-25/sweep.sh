/usr/bin/time -f "%e s wall %U s user" /work/bins/grit-new bench sweep --angle 45 --ppd 32 --variants default --samples 5 --impacts 70 --out sweep32-new > sweep-new.log 2>&1
/usr/bin/time -f "%e s wall %U s user" /work/bins/grit-old17 bench sweep --angle 45 --ppd 32 --variants default --samples 5 --impacts 70 --out sweep32-old17 > sweep-old17.log 2>&1
touch SWEEPDONE
