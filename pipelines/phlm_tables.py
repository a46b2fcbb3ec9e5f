#!/usr/bin/env python3
"""Markdown tables of filter-phlm's pipelines from compare's JSON / the tuning CSV (no statistics are computed here:
means, 95% intervals and paired differences are compare's, docs/compare.md).

  phlm_tables.py tuning TUNING.csv
      one table per method of the sweep (rows: setting; columns: tuning sequences, mean PSNR, mean flicker), the
      chosen setting (highest mean PSNR over the sequences) stated under it
  phlm_tables.py scenes OUT_DIR SCENE[,SCENE...] SEQ[,SEQ...] [A:B,A:B...]
      per scene: mean PSNR (RGB) over frames with its 95% interval and the steady-state mean (after compare's
      --warmup frames), mean flicker; the mean over the scenes; then the paired differences A - B (PSNR, and
      flicker) with their 95% intervals for each PAIR "A:B" (names as given to compare --names)
  phlm_tables.py scenes-by-row OUT_DIR ...
      the same, with the paired differences one row per pair and one column per scene, PSNR only (ablations)
Fields compare does not write (an older compare without intervals) are shown as "n/a".
"""
import csv
import json
import math
import os
import sys
from collections import OrderedDict, defaultdict


def fmt(v, digits=2, sign=False):
    if v is None:
        return "n/a"
    if isinstance(v, str):
        return v
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:+.{digits}f}" if sign else f"{v:.{digits}f}"


def tuning(path):
    rows = list(csv.DictReader(open(path)))
    methods = OrderedDict()
    for r in rows:
        methods.setdefault(r["method"], OrderedDict()).setdefault(r["setting"], OrderedDict())[r["sequence"]] = r
    seqs = list(OrderedDict((r["sequence"], 1) for r in rows))
    def key(setting):
        parts = []
        for item in setting.split("/"):
            name, _, value = item.partition("=")
            try:
                parts.append((name, 0, float(value), ""))
            except ValueError:
                parts.append((name, 1, 0.0, value))
        return parts

    out = []
    for method, settings in methods.items():
        settings = OrderedDict(sorted(settings.items(), key=lambda kv: key(kv[0])))
        out.append(f"### {method}\n")
        out.append("| setting | " + " | ".join(seqs) + " | mean PSNR | mean flicker |")
        out.append("|---|" + "---|" * (len(seqs) + 2))
        best, best_psnr = None, -1e30
        for setting, by_seq in settings.items():
            ps = [float(by_seq[s]["psnr_rgb_db"]) for s in seqs if s in by_seq]
            fl = [float(by_seq[s]["flicker"]) for s in seqs if s in by_seq and by_seq[s]["flicker"] not in ("", "None")]
            mp = sum(ps) / len(ps)
            mf = sum(fl) / len(fl) if fl else None
            if mp > best_psnr:
                best, best_psnr = setting, mp
            cells = [fmt(float(by_seq[s]["psnr_rgb_db"])) if s in by_seq else "" for s in seqs]
            out.append(f"| {setting} | " + " | ".join(cells) + f" | {fmt(mp)} | {fmt(mf, 4)} |")
        out.append("")
        out.append(f"Highest mean PSNR over the tuning sequences: **{method} {best}** ({fmt(best_psnr)} dB).\n")
    print("\n".join(out))


def load(out_dir, scene):
    return json.load(open(os.path.join(out_dir, scene, "metrics.json")))


def metric(seq, key):
    m = seq.get(key) or {}
    mean = m.get("mean")
    if isinstance(mean, str):
        mean = float(mean)
    ci = m.get("ci95")
    steady = m.get("steady") or {}
    return mean, ci, steady.get("mean"), steady.get("ci95")


def cell(mean, ci, digits=2, sign=False):
    s = fmt(mean, digits, sign)
    if ci:
        s += f" [{fmt(ci[0], digits, sign)}, {fmt(ci[1], digits, sign)}]"
    return s


def scenes(out_dir, scene_list, seq_list, pair_list, by_row=False):
    data = {s: load(out_dir, s) for s in scene_list}
    out = ["| scene | " + " | ".join(seq_list) + " |", "|---|" + "---|" * len(seq_list)]
    sums = defaultdict(list)
    for s in scene_list:
        by = {q["name"]: q for q in data[s]["sequences"]}
        cells = []
        for name in seq_list:
            if name not in by:
                cells.append("")
                continue
            p, pci, ps, _ = metric(by[name], "psnr_rgb")
            f, _, _, _ = metric(by[name], "flicker")
            sums[name].append((p, f, ps))
            c = cell(p, pci)
            if ps is not None:
                c += f" (steady {fmt(ps)})"
            cells.append(c + f" / {fmt(f, 4)}")
        out.append(f"| {s} | " + " | ".join(cells) + " |")
    means = []
    for name in seq_list:
        v = sums.get(name, [])
        if not v:
            means.append("")
            continue
        mp = sum(x[0] for x in v) / len(v)
        mf = sum(x[1] for x in v if x[1] is not None) / max(1, sum(1 for x in v if x[1] is not None))
        means.append(f"{fmt(mp)} / {fmt(mf, 4)}")
    out.append("| mean of the scenes | " + " | ".join(means) + " |")
    print("\n".join(out))
    if not pair_list:
        return
    if by_row:
        pairs_by_row(data, scene_list, pair_list)
        return
    for part, title in (("all", "all frames"), ("steady", "steady state (after compare's --warmup frames)")):
        print()
        print(f"Paired differences A - B, {title}: mean over frames [95% interval] (compare's `paired`):\n")
        print("| scene | " + " | ".join(f"{a} - {b}: PSNR dB / flicker" for a, b in pair_list) + " |")
        print("|---|" + "---|" * len(pair_list))
        for s in scene_list:
            paired = data[s].get("paired")
            cells = []
            for a, b in pair_list:
                if paired is None:
                    cells.append("n/a")
                    continue
                parts = []
                for key, digits in (("psnr_rgb", 2), ("flicker", 4)):
                    hit = None
                    for p in paired:
                        if p.get("metric") == key and {p.get("a"), p.get("b")} == {a, b}:
                            hit = p
                            break
                    if hit is not None and part == "steady":
                        hit = hit.get("steady")
                    if hit is None or hit.get("mean_difference") is None:
                        parts.append("n/a")
                        continue
                    sign = 1.0 if (part == "all" and hit["a"] == a) or (part == "steady" and _orient(paired, key, a, b)) else -1.0
                    d = sign * float(hit["mean_difference"])
                    ci = hit.get("ci95")
                    ci = sorted([sign * float(ci[0]), sign * float(ci[1])]) if ci else None
                    parts.append(cell(d, ci, digits, sign=True))
                cells.append(" / ".join(parts))
            print(f"| {s} | " + " | ".join(cells) + " |")


def paired_value(paired, key, a, b, part):
    """(mean of a - b, sorted 95% interval or None) from compare's `paired`, over all frames or the steady state."""
    for p in paired or []:
        if p.get("metric") == key and {p.get("a"), p.get("b")} == {a, b}:
            sign = 1.0 if p["a"] == a else -1.0
            hit = p.get("steady") if part == "steady" else p
            if hit is None or hit.get("mean_difference") is None:
                return None, None
            ci = hit.get("ci95")
            return sign * float(hit["mean_difference"]), (sorted([sign * float(ci[0]), sign * float(ci[1])]) if ci else None)
    return None, None


def pairs_by_row(data, scene_list, pair_list):
    """Many pairs (an ablation): one row per pair, one column per scene, PSNR only."""
    for part, title in (("all", "all frames"), ("steady", "steady state (after compare's --warmup frames)")):
        print()
        print(f"Paired differences A - B of PSNR (RGB, dB), {title}: mean over frames [95% interval] (compare's `paired`):\n")
        print("| A - B | " + " | ".join(scene_list) + " |")
        print("|---|" + "---|" * len(scene_list))
        for a, b in pair_list:
            cells = []
            for s in scene_list:
                d, ci = paired_value(data[s].get("paired"), "psnr_rgb", a, b, part)
                cells.append(cell(d, ci, 2, sign=True) if d is not None else "n/a")
            print(f"| {a} - {b} | " + " | ".join(cells) + " |")


def _orient(paired, key, a, b):
    """True when compare's entry for {a, b} and `key` is a - b (not b - a)."""
    for p in paired:
        if p.get("metric") == key and {p.get("a"), p.get("b")} == {a, b}:
            return p["a"] == a
    return True


def main():
    if len(sys.argv) >= 3 and sys.argv[1] == "tuning":
        tuning(sys.argv[2])
    elif len(sys.argv) >= 5 and sys.argv[1] in ("scenes", "scenes-by-row"):
        pairs = [tuple(p.split(":", 1)) for p in sys.argv[5].split(",")] if len(sys.argv) > 5 and sys.argv[5] else []
        scenes(sys.argv[2], sys.argv[3].split(","), sys.argv[4].split(","), pairs, sys.argv[1] == "scenes-by-row")
    else:
        sys.stderr.write(__doc__)
        sys.exit(1)


if __name__ == "__main__":
    main()
