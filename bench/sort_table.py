#!/usr/bin/env python3
"""Joins `snell bench sort --json` and the CUB peer's JSON (same run, same GPU)
into one table: median times, pairs per second and the snell/CUB ratio.

usage: bench/sort_table.py SNELL.json CUB.json OUT.md OUT.json
"""
import json
import sys


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    snell = json.load(open(sys.argv[1]))
    cub = json.load(open(sys.argv[2]))
    peer = {(r["pairs"], r["key_bits"]): r for r in cub["results"]}
    rows = []
    for r in snell["results"]:
        c = peer.get((r["pairs"], r["key_bits"]))
        rows.append({
            "pairs": r["pairs"],
            "key_bits": r["key_bits"],
            "snell_median_ms": r["median_ms"],
            "snell_gpairs_per_s": r["gpairs_per_s"],
            "snell_correct": r["correct"],
            "shape": f"{r['workgroup_size']}x{r['keys_per_thread']}",
            "cub_median_ms": c["median_ms"] if c else None,
            "cub_gpairs_per_s": c["gpairs_per_s"] if c else None,
            "ratio_snell_over_cub": (r["gpairs_per_s"] / c["gpairs_per_s"]) if c else None,
        })
    lines = [
        "# Radix sort: snell (Vulkan compute) vs CUB, one run, one GPU",
        "",
        f"- GPU: {snell['device']['name']}; Vulkan driver: {snell['device']['driver']} {snell['device']['driver_info']} (Vulkan {snell['device']['vulkan']})",
        f"- CUB: {cub['implementation']}, CUDA driver {cub['cuda_driver']}",
        f"- median of {snell['runs']} runs after {snell['warmup']} warm-up; GPU timestamps (snell), CUDA events (CUB)",
        "- 32-bit values; random keys; every row checked against std::sort",
        "",
        "| pairs | key bits | snell workgroup x keys | snell ms | snell Gpairs/s | CUB ms | CUB Gpairs/s | snell / CUB |",
        "| ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        cub_ms = f"{r['cub_median_ms']:.4f}" if r["cub_median_ms"] else "-"
        cub_rate = f"{r['cub_gpairs_per_s']:.2f}" if r["cub_gpairs_per_s"] else "-"
        ratio = f"{r['ratio_snell_over_cub']:.2f}x" if r["ratio_snell_over_cub"] else "-"
        lines.append(f"| 2^{r['pairs'].bit_length() - 1} | {r['key_bits']} | {r['shape']} | {r['snell_median_ms']:.4f} | "
                     f"{r['snell_gpairs_per_s']:.2f} | {cub_ms} | {cub_rate} | {ratio} |")
    open(sys.argv[3], "w").write("\n".join(lines) + "\n")
    json.dump({"device": snell["device"]["name"], "driver": snell["device"]["driver"], "cub": cub["implementation"],
               "rows": rows}, open(sys.argv[4], "w"), indent=2)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
