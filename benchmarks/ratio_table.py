#!/usr/bin/env python3
"""Turns Google Benchmark JSON into a Markdown ratio table: for every argument (map size), the
time of each benchmark, its ratio to the first one named, and the growth exponent of the first
between consecutive sizes (log t2/t1 / log n2/n1; 2 = quadratic). Usage:
    ratio_table.py results.json BM_Baseline BM_Other [BM_More ...]"""
import json
import math
import sys


def main():
    path, names = sys.argv[1], sys.argv[2:]
    with open(path) as f:
        runs = [b for b in json.load(f)["benchmarks"] if b.get("run_type", "iteration") == "iteration"]
    times = {}  # (name, arg) -> real time in the benchmark's unit
    unit = {}
    for b in runs:
        name, _, arg = b["name"].partition("/")
        times[(name, int(arg.split("/")[0]))] = b["real_time"]
        unit[name] = b["time_unit"]
    args = sorted({a for (n, a) in times if n == names[0]})
    header = ["n"] + [f"{n} [{unit.get(n, '?')}]" for n in names] + [f"{n} / {names[0]}" for n in names[1:]]
    header.append(f"growth exponent of {names[0]}")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for a in args:
        base = times.get((names[0], a))
        cells = [str(a)] + [f"{times[(n, a)]:.1f}" if (n, a) in times else "-" for n in names]
        cells += [f"{times[(n, a)] / base:.1f}x" if (n, a) in times and base else "-" for n in names[1:]]
        previous = args[args.index(a) - 1] if args.index(a) > 0 else None
        cells.append(f"{math.log(base / times[(names[0], previous)]) / math.log(a / previous):.2f}" if previous else "-")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
