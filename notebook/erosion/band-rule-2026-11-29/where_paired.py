"""Where the loss is made in two boxes that meet the same grains, paired sample by sample.
usage: where_paired.py STD_REMOVED.tsv BIG_REMOVED.tsv BLOCK [FIRST]
Per angle, block and zone (where_lost.py's): the mass removed per impact (mg/g) in each box and
the paired difference big - std over the samples both have, mean ± standard error."""
import sys

from where_lost import ZONES, mean_se, pool


def main():
    block = int(sys.argv[3])
    first = int(sys.argv[4]) if len(sys.argv) > 4 else 0
    std, big = pool(sys.argv[1], block, first), pool(sys.argv[2], block, first)
    print("| angle | impacts | samples | zone | 3.0 Dg box | 4.5 Dg box | difference |")
    print("|---|---|---|---|---|---|---|")
    for angle, start in sorted({(k[0], k[2]) for k in big}, key=lambda k: (float(k[0]), k[1])):
        both = sorted(k for k in big if k[0] == angle and k[2] == start and k in std)
        if not both:
            continue
        for z in ["all"] + ZONES:
            def val(d, k):
                return (sum(d[k].values()) if z == "all" else d[k][z]) / block
            s = [val(std, k) for k in both]
            b = [val(big, k) for k in both]
            print(f"| {angle}° | {start + 1}–{start + block} | {len(both)} | {z} | {mean_se(s)} |"
                  f" {mean_se(b)} | {mean_se([q - p for p, q in zip(s, b)])} |")


if __name__ == "__main__":
    main()
