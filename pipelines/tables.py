#!/usr/bin/env python3
"""The one table formatter of pipelines/ (docs/pipelines.md, "Tables"): every Markdown or CSV table the scripts
write, from compare's CSV / JSON. The means, 95% intervals and paired differences are compare's (docs/compare.md);
this module only picks and formats them. The few numbers compare does not compute are in the last section,
"Numbers compare does not compute", named as such (issue 21: they belong in compare, not in the scripts).

Tables:
  tables.py scenes OUT_DIR SCENE[,SCENE...] SEQ[,SEQ...] [A:B,A:B...]
      per scene (OUT_DIR/SCENE/metrics.json): mean PSNR (RGB) over frames with its 95% interval and the
      steady-state mean (after compare's --warmup frames), mean flicker; the mean of those over the scenes (not
      compare's: one compare run sees one scene); then the paired differences A - B (PSNR, and flicker) with
      their 95% intervals for each PAIR "A:B" (names as given to compare --names); when compare ran with
      --regions motion, a table per region (share, mean PSNR [95%] / pooled PSNR) and the paired differences per
      region
  tables.py scenes-by-row OUT_DIR ...
      the same, with the paired differences one row per pair and one column per scene, PSNR only (ablations)
  tables.py upsample-st SCENE_DIR SHADE_LOW_MS SHADE_FULL_MS [SS_JSON SS_LABEL]
      seed 000's Table 1 rows of one scene (SCENE_DIR/metrics.json): shade ms, upsampling ms (compare's
      compute_ms), total, full-resolution shade ms, speed-up, PSNR, and the PSNR against the supersampled reference
      of SS_JSON; then herzog's margins over spatial and temporal (compare's paired differences)
  tables.py tuning TUNING.csv
      one table per method of the sweep (rows: setting; columns: tuning sequences, the mean of compare's means
      over the sequences, PSNR and flicker), the chosen setting (highest mean PSNR over the sequences) under it
  tables.py tuning-rows METRICS_JSON SEQUENCE RUN...
      rows "method,setting,sequence,psnr_rgb_db,flicker" of TUNING.csv: RUN i ("METHOD SETTING ...") is compare's
      sequence named i
  tables.py tuning-region-rows METRICS_JSON SEQUENCE RUN...
      rows "method,setting,sequence,region,share,psnr_rgb_db,psnr_rgb_pooled_db,flicker" of TUNING-REGIONS.csv, one
      per region (all, static, moving, disoccluded; compare --regions motion): compare's mean PSNR over the frames
      that have the region, its pooled PSNR, the region's pixel share; empty fields for an empty region
  tables.py tuning-regions TUNING-REGIONS.csv
      per method, one row per setting and one column per region: the mean over the tuning sequences that have the
      region of compare's mean PSNR in it; then the optimum per region (highest such mean), beside the whole-frame one
  tables.py tuned-variants TUNING-REGIONS.csv METHOD[,METHOD...] RUN...
      filter-phlm.sh VARIANTS lines "METHOD-tuned-REGION METHOD ARGUMENTS" for the static and moving optimum of each
      METHOD (RUN i: "METHOD SETTING ARGUMENTS...", the tuning script's runs)
  tables.py interval JSON SEQUENCE METRIC
      "mean,ci_low,ci_high" of a sequence's metric (%.2f; empty fields when absent; "inf" kept)
  tables.py value JSON SEQUENCE KEY[.KEY...] [DIGITS]
      one value of a sequence's JSON object (e.g. compute_ms, psnr_latency.latency_frames), DIGITS decimals
      (default: as written); "nan" when absent
  tables.py paired-rows JSON SCENE SCORE METRIC
      rows "scene,score,metric,a,b,frames,mean_difference_db,ci_low,ci_high" of compare's paired differences
  tables.py region-table OUT_DIR JSON_NAME SCENE[,SCENE...] SEQ[,SEQ...] [A:B,A:B...]
      the per-region tables of `scenes` alone (share, mean PSNR [95%] / pooled PSNR per region, then the paired
      differences per region) from OUT_DIR/SCENE/JSON_NAME (e.g. morph-120hz.sh's inbetween.json)
  tables.py morph-summary SUMMARY.csv
      morph-120hz.sh's summary table (Markdown) from its summary.csv
  tables.py noise-floor FLOOR_JSON METRICS_JSON SPP SPP4
      the reference's noise floor: compare's PSNR (RGB) of the SPP-spp reference against the SPP4-spp one
      (FLOOR_JSON: mean over its frames with the 95% interval, and pooled), and whether the best mean PSNR of
      METRICS_JSON comes within 10 dB of it (then the table cannot rank methods finer than the reference's noise)
Numbers compare does not compute (see that section):
  tables.py csv-mean CSV COLUMN [DIGITS]          mean of a column (render-gbuffer's timings.csv)
  tables.py pass-ms-mean TIMINGS.csv [DIGITS]     mean over frames of the sum of render-gbuffer's pass columns
  tables.py mean [DIGITS]                         of the numbers on stdin (one per line; the lagMs headers)
  tables.py median-ms                             of the runs timed as "START END" lines on stdin (seconds)
  tables.py per-frame TOTAL COUNT [MINUS]         (TOTAL - MINUS) / COUNT, %.2f
  tables.py regions FACTOR M.csv S.csv C.csv L.csv METHOD...   morph-120hz-regions.sh's split of the error
Fields compare does not write (an older compare without intervals) are shown as "n/a".
"""
import csv
import json
import math
import os
import sys
from collections import OrderedDict, defaultdict


def num(v):
    """A JSON number, or compare's "inf" / "-inf" strings, as a float; None for anything else."""
    if v is None:
        return None
    if isinstance(v, str):
        return math.inf if v == "inf" else -math.inf if v == "-inf" else None
    return float(v)


def fmt(v, digits=2, sign=False, missing="n/a"):
    if v is None:
        return missing
    if isinstance(v, str):
        return v
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:+.{digits}f}" if sign else f"{v:.{digits}f}"


def fmt_value(v, digits=2):
    """A JSON value as the workflow summary shows it: a number or compare's "inf", "-" for anything else."""
    return fmt(num(v), digits, missing="-")


def with_ci(m, digits=2):
    """"mean [low, high]" of one of compare's {mean, ci95} objects, "-" for what is missing (the workflow summary)."""
    if not m:
        return "-"
    ci = m.get("ci95") or [None, None]
    return f"{fmt_value(m.get('mean'), digits)} [{fmt_value(ci[0], digits)}, {fmt_value(ci[1], digits)}]"


def sequences(path):
    """compare's JSON sequences by name."""
    return {q["name"]: q for q in json.load(open(path))["sequences"]}


def tuning(path):
    rows = list(csv.DictReader(open(path)))
    methods = OrderedDict()
    for r in rows:
        methods.setdefault(r["method"], OrderedDict()).setdefault(r["setting"], OrderedDict())[r["sequence"]] = r
    seqs = list(OrderedDict((r["sequence"], 1) for r in rows))
    out = []
    for method, settings in methods.items():
        settings = OrderedDict(sorted(settings.items(), key=lambda kv: _setting_key(kv[0])))
        out.append(f"### {method}\n")
        out.append("| setting | " + " | ".join(seqs) + " | mean PSNR | mean flicker |")
        out.append("|---|" + "---|" * (len(seqs) + 2))
        best, best_psnr = None, -1e30
        for setting, by_seq in settings.items():
            ps = [float(by_seq[s]["psnr_rgb_db"]) for s in seqs if s in by_seq]
            fl = [float(by_seq[s]["flicker"]) for s in seqs if s in by_seq and by_seq[s]["flicker"] not in ("", "None")]
            # The mean over the tuning sequences of compare's per-sequence means: not compare's (see the last
            # section's note); the choice criterion of docs/filter-phlm.md.
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
    # "mean of the scenes": the mean of compare's per-scene means (not compare's: one compare run sees one scene).
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
    region_tables(data, scene_list, seq_list, pair_list)
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
                        if p.get("metric") == key and {p.get("a"), p.get("b")} == {a, b} and whole_frame(p):
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


def paired_value(paired, key, a, b, part, region="all"):
    """(mean of a - b, sorted 95% interval or None) from compare's `paired`, over all frames or the steady state."""
    for p in paired or []:
        if p.get("metric") == key and {p.get("a"), p.get("b")} == {a, b} and p.get("region", "all") == region:
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
        if p.get("metric") == key and {p.get("a"), p.get("b")} == {a, b} and whole_frame(p):
            return p["a"] == a
    return True


def whole_frame(p):
    """True for a paired entry of the whole frame (compare --regions adds entries per region)."""
    return p.get("region", "all") == "all"


REGIONS = ("static", "moving", "disoccluded")


def region_tables(data, scene_list, seq_list, pair_list):
    """With compare --regions motion (docs/compare.md, Regions): per scene and region the pixel share, then per
    sequence the mean PSNR (RGB) over frames [95% interval] / the pooled PSNR (PSNR of the pooled squared error);
    then the paired differences A - B of the mean PSNR per region. Nothing when no scene has regions."""
    if not any("regions" in q for s in scene_list for q in data[s]["sequences"]):
        return
    print()
    print("Per region (compare --regions motion): share of the pixels; mean PSNR (RGB, dB) over frames [95% interval]"
          " / pooled PSNR (of the squared error over all the region's pixels and frames):\n")
    print("| scene | region | share | " + " | ".join(seq_list) + " |")
    print("|---|---|---|" + "---|" * len(seq_list))
    for s in scene_list:
        by = {q["name"]: q for q in data[s]["sequences"]}
        for region in ("all",) + REGIONS:
            share, cells = None, []
            for name in seq_list:
                q = by.get(name)
                if q is None:
                    cells.append("")
                    continue
                if region == "all":
                    m, pooled, share = q.get("psnr_rgb") or {}, q.get("psnr_rgb_pooled") or {}, 1.0
                else:
                    r = (q.get("regions") or {}).get(region) or {}
                    m, pooled = r.get("psnr_rgb") or {}, r.get("psnr_rgb_pooled") or {}
                    share = r.get("share", share)
                if num(m.get("mean")) is None:  # an empty region (e.g. no static pixels yet)
                    cells.append("n/a")
                else:
                    cells.append(cell(num(m.get("mean")), m.get("ci95")) + " / " + fmt(num(pooled.get("value"))))
            print(f"| {s} | {region} | {fmt(100.0 * share, 1) + ' %' if share is not None else 'n/a'} | "
                  + " | ".join(cells) + " |")
    if not pair_list:
        return
    print()
    print("Paired differences A - B of the mean PSNR (RGB, dB) per region [95% interval] (compare's `paired`):\n")
    print("| scene | region | " + " | ".join(f"{a} - {b}" for a, b in pair_list) + " |")
    print("|---|---|" + "---|" * len(pair_list))
    for s in scene_list:
        for region in REGIONS:
            cells = []
            for a, b in pair_list:
                d, ci = paired_value(data[s].get("paired"), "psnr_rgb", a, b, "all", region)
                cells.append(cell(d, ci, 2, sign=True) if d is not None else "n/a")
            print(f"| {s} | {region} | " + " | ".join(cells) + " |")


def region_table(out_dir, json_name, scene_list, seq_list, pair_list):
    """`scenes`' per-region tables alone, from OUT_DIR/SCENE/JSON_NAME; says so when compare ran without regions."""
    data = {s: json.load(open(os.path.join(out_dir, s, json_name))) for s in scene_list}
    if not any("regions" in q for s in scene_list for q in data[s]["sequences"]):
        print("No per-region values: compare ran without --regions motion.")
        return
    region_tables(data, scene_list, seq_list, pair_list)


def upsample_st(scene_dir, low, full, ss_json=None, ss_label=None):
    """Seed 000's Table 1 rows of one scene. LOW and FULL are the shading ms as csv-mean printed them ("-" when
    none); the sums and the speed-up use the printed (rounded) values, as the table shows them."""
    def as_number(text):
        try:
            return float(text)
        except ValueError:
            return 0.0
    report = json.load(open(os.path.join(scene_dir, "metrics.json")))
    ss = sequences(ss_json) if ss_json else None
    head = "| method | shade ms | up ms | total ms | full-res shade ms | speed-up | PSNR dB |"
    if ss is not None:
        head += f" PSNR vs {ss_label} |"
    print(head)
    print("|---|---|---|---|---|---|---|" + ("---|" if ss is not None else ""))
    for q in report["sequences"]:
        up = fmt(num(q.get("compute_ms")), 3, missing="-")
        total = as_number(low) + (0.0 if up == "-" else float(up))
        psnr = fmt(num((q.get("psnr_rgb") or {}).get("mean")), 3, missing="-")
        row = (f"| {q['name']} | {low} | {up} | {total:.3f} | {full} | "
               f"{(as_number(full) / total if total > 0 else 0):.1f}x | {psnr} |")
        if ss is not None:
            hit = ss.get(q["name"])
            row += " " + (fmt(num((hit.get("psnr_rgb") or {}).get("mean")), 3, missing="-") if hit else "-") + " |"
        print(row)
    # The reading of Table 1: herzog's margin over both baselines (compare's paired differences).
    paired = report.get("paired")
    hs, _ = paired_value(paired, "psnr_rgb", "herzog", "spatial", "all")
    ht, _ = paired_value(paired, "psnr_rgb", "herzog", "temporal", "all")
    if hs is not None and ht is not None:
        print()
        print(f"herzog - spatial: {hs:+.2f} dB, herzog - temporal: {ht:+.2f} dB.")


def tuning_rows(path, seq, runs):
    """TUNING.csv rows of one tuning sequence: compare's mean PSNR and flicker of run i (compare's sequence "i")."""
    by_name = sequences(path)
    for i, run in enumerate(runs):
        method, label = run.split()[:2]
        s = by_name[str(i)]
        print(f"{method},{label},{seq},{s['psnr_rgb']['mean']},{s['flicker']['mean']}")


TUNING_REGIONS = ("all",) + REGIONS


def tuning_region_rows(path, seq, runs):
    """TUNING-REGIONS.csv rows of one tuning sequence: per run (compare's sequence "i") and region, compare's mean
    PSNR (RGB) over the frames with the region, its pooled PSNR, the region's share and flicker."""
    def f(v):
        v = num(v)
        return "" if v is None else repr(v)
    by_name = sequences(path)
    for i, run in enumerate(runs):
        method, label = run.split()[:2]
        q = by_name[str(i)]
        for region in TUNING_REGIONS:
            r = q if region == "all" else (q.get("regions") or {}).get(region)
            if r is None:
                continue  # compare ran without --regions
            share = 1.0 if region == "all" else r.get("share")
            print(",".join([method, label, seq, region, f(share), f((r.get("psnr_rgb") or {}).get("mean")),
                            f((r.get("psnr_rgb_pooled") or {}).get("value")), f((r.get("flicker") or {}).get("mean"))]))


def _tuning_region_means(path):
    """{method: {setting: {region: (mean over the sequences of compare's mean PSNR, sequences)}}} and the sequences
    per region. The mean over the tuning sequences is not compare's (one compare run sees one sequence), as in
    `tuning`; a sequence without pixels of a region (e.g. no static pixels under a moving camera) is left out of
    that region's mean."""
    acc = OrderedDict()
    seqs = defaultdict(list)
    for r in csv.DictReader(open(path)):
        v = num(float(r["psnr_rgb_db"])) if r["psnr_rgb_db"] not in ("", "inf") else None
        if v is None:
            continue
        if r["sequence"] not in seqs[r["region"]]:
            seqs[r["region"]].append(r["sequence"])
        acc.setdefault(r["method"], OrderedDict()).setdefault(r["setting"], OrderedDict()).setdefault(
            r["region"], []).append(v)
    out = OrderedDict()
    for method, settings in acc.items():
        out[method] = OrderedDict()
        for setting, by_region in settings.items():
            out[method][setting] = {g: (sum(v) / len(v), len(v)) for g, v in by_region.items()}
    return out, seqs


def _setting_key(setting):
    """Sort key of a tuning setting label "name=value/name=value": numeric values in numeric order."""
    parts = []
    for item in setting.split("/"):
        name, _, value = item.partition("=")
        try:
            parts.append((name, 0, float(value), ""))
        except ValueError:
            parts.append((name, 1, 0.0, value))
    return parts


def _tuning_optimum(settings, region):
    best = None
    for setting, by_region in settings.items():
        m = by_region.get(region)
        if m is not None and (best is None or m[0] > best[1]):
            best = (setting, m[0])
    return best


def tuning_regions(path):
    means, seqs = _tuning_region_means(path)
    out = ["Per region (compare --regions motion): the mean over the tuning sequences that have the region of compare's"
           " mean PSNR (RGB, dB) in it. Sequences per region: "
           + "; ".join(f"{g}: {', '.join(seqs[g]) if seqs[g] else 'none'}" for g in TUNING_REGIONS) + ".\n"]
    for method, settings in means.items():
        out.append(f"### {method} per region\n")
        out.append("| setting | " + " | ".join(TUNING_REGIONS) + " |")
        out.append("|---|" + "---|" * len(TUNING_REGIONS))
        for setting, by_region in sorted(settings.items(), key=lambda kv: _setting_key(kv[0])):
            out.append(f"| {setting} | " + " | ".join(fmt(by_region[g][0]) if g in by_region else "n/a"
                                                       for g in TUNING_REGIONS) + " |")
        out.append("")
        parts = []
        for g in TUNING_REGIONS:
            best = _tuning_optimum(settings, g)
            parts.append(f"{'whole frame' if g == 'all' else g}: **{best[0]}** ({fmt(best[1])} dB)" if best
                         else f"{g}: none (no sequence has the region)")
        out.append(f"Optimum of {method} per region: " + "; ".join(parts) + ".\n")
    print("\n".join(out))


def tuned_variants(path, methods, runs):
    means, _ = _tuning_region_means(path)
    args = {}
    for run in runs:
        method, label, *rest = run.split()
        args[(method, label)] = " ".join(rest)
    for method in methods:
        for region in ("static", "moving"):
            best = _tuning_optimum(means.get(method, {}), region)
            if best is not None and (method, best[0]) in args:
                print(f"{method}-tuned-{region} {method} {args[(method, best[0])]}")


def interval(path, seq, key):
    def f(v):  # compare writes +infinity (an identical frame) as "inf": shown, never dropped
        return "" if v is None else "%.2f" % v if isinstance(v, (int, float)) else str(v)
    q = sequences(path).get(seq)
    if q is None:
        print(",,")
        return
    m = q.get(key) or {}
    ci = m.get("ci95") or [None, None]
    print(",".join(f(v) for v in (m.get("mean"), ci[0], ci[1])))


def value(path, seq, keys, digits=None):
    v = sequences(path).get(seq)
    for k in keys.split("."):
        v = v.get(k) if isinstance(v, dict) else None
    if v is None:
        print("nan")
    elif digits is not None and isinstance(v, (int, float)):
        print(f"{v:.{int(digits)}f}")
    else:
        print(v)


def paired_rows(path, scene, score, key):
    def f(v):
        return "" if v is None or isinstance(v, str) else "%.3f" % v
    for p in json.load(open(path)).get("paired", []):
        if p["metric"] != key or not whole_frame(p):
            continue
        ci = p.get("ci95") or [None, None]
        print(",".join([scene, score, p["metric"], p["a"], p["b"], str(p["frames"]), f(p["mean_difference"]),
                        f(ci[0]), f(ci[1])]))


def noise_floor(floor_path, metrics_path, spp, spp4):
    q = json.load(open(floor_path))["sequences"][0]
    m = q.get("psnr_rgb") or {}
    floor = num(m.get("mean"))
    pooled = num((q.get("psnr_rgb_pooled") or {}).get("value"))
    line = (f"Noise floor: PSNR (RGB) of the {spp}-spp reference against a {spp4}-spp render of its first "
            f"{m.get('frames', 0)} frames: {cell(floor, m.get('ci95'))} dB (pooled {fmt(pooled)} dB).")
    best = None
    for s in json.load(open(metrics_path))["sequences"]:
        v = num((s.get("psnr_rgb") or {}).get("mean"))
        if v is not None and math.isfinite(v) and (best is None or v > best[1]):
            best = (s["name"], v)
    if best is not None and floor is not None and math.isfinite(floor):
        if best[1] > floor - 10.0:
            line += (f" The best mean PSNR ({best[0]}, {fmt(best[1])} dB) is within 10 dB of it: differences between"
                     " methods near the top are partly the reference's noise.")
        else:
            line += f" The best mean PSNR ({best[0]}, {fmt(best[1])} dB) is {fmt(floor - best[1])} dB below it."
    print(line)


def morph_summary(path):
    print("| scene | method | L | in-between | in-between, shown | all | perceived | perceived, shown | "
          "blur (lag removed) | lag ms | compute ms | command ms | render ms |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    with open(path) as f:
        next(f)
        for line in f:
            c = line.rstrip("\n").split(",")
            c += [""] * (17 - len(c))
            print(f"| {c[0]} | {c[1]} | {c[2]} | {c[3]} [{c[4]}, {c[5]}] | {c[6]} [{c[7]}, {c[8]}] | "
                  + " | ".join(c[9:17]) + " |")


# --- Numbers compare does not compute ------------------------------------------------------------------------
# These are statistics the pipelines report that compare has no input for (render-gbuffer's timings.csv, wall
# times of whole commands, EXR header values of --perceive outputs) or does not compute (morph-120hz-regions.sh's
# split of the error by region). They are here, named, rather than in shell or awk, until compare (or the tool
# that measures them) reports them.

def csv_mean(path, column, digits=3):
    """Mean of a named column of a CSV file, empty cells skipped ("-" when none): render-gbuffer's timings.csv."""
    vals = [float(r[column]) for r in csv.DictReader(open(path)) if r.get(column) not in (None, "")]
    print(f"{sum(vals) / len(vals):.{int(digits)}f}" if vals else "-")


def pass_ms_mean(path, digits=2):
    """Mean over the frames of render-gbuffer's timings.csv of the sum of its pass columns (every column after
    frame and time): the render time of one frame."""
    rows = list(csv.reader(open(path)))[1:]
    sums = [sum(float(x) for x in r[2:] if x != "") for r in rows]  # an empty cell: a pass not run
    print(f"{sum(sums) / len(sums):.{int(digits)}f}" if sums else "nan")


def stdin_numbers():
    return [float(line) for line in sys.stdin if line.strip()]


def mean(digits=2):
    v = stdin_numbers()
    print(f"{sum(v) / len(v):.{int(digits)}f}" if v else "nan")


def median_ms():
    """Median in ms of the runs timed as "START END" lines (seconds, date +%s.%N), each run's time rounded to
    3 decimals first."""
    times = []
    for line in sys.stdin:
        if line.strip():
            a, b = (float(x) for x in line.split())
            times.append(float(f"{(b - a) * 1000:.3f}"))
    times.sort()
    n = len(times)
    print(f"{times[n // 2]:.3f}" if n % 2 else f"{(times[n // 2 - 1] + times[n // 2]) / 2:.3f}")


def per_frame(total, count, minus="0"):
    n = int(count)
    print(f"{(float(total) - float(minus)) / (n if n > 0 else 1):.2f}")


def regions(factor, m_csv, s_csv, c_csv, l_csv, methods):
    """Per method over the in-between frames: mean PSNR, mean share of each region in the MSE, and the PSNR with a
    region's error removed (morph-120hz-regions.sh describes the regions), from compare's masked CSVs."""
    factor = int(factor)

    def rows(path):
        out = {}
        for r in csv.DictReader(open(path)):
            f = int(r["frame"])
            if f % factor:
                out[(r["sequence"], f)] = r
        return out

    M, S, C, L = rows(m_csv), rows(s_csv), rows(c_csv), rows(l_csv)

    def mse_in(r):
        p = float(r["psnr_rgb_in_db"]) if r["psnr_rgb_in_db"] not in ("", "inf") else math.inf
        return 0.0 if math.isinf(p) else 10 ** (-p / 10)

    names = ("M", "D", "S", "C", "L", "U")
    print("method,frames,psnr_db,mse," + ",".join("share_" + r for r in names) + ","
          + ",".join("fraction_" + r for r in names) + "," + ",".join("psnr_without_%s_db" % r for r in names))
    for m in methods:
        keys = sorted(k for k in M if k[0] == m)
        acc = {k: 0.0 for k in ["psnr", "mse"] + [p + r for p in "sfw" for r in names]}
        psnr = lambda e: 10 * math.log10(1 / e) if e > 0 else math.inf
        for k in keys:
            total = float(M[k]["mse_rgb"])
            fm, fs, fc, fl = (float(x[k]["mask_fraction"]) for x in (M, S, C, L))
            em, es, ec, el = fm * mse_in(M[k]), fs * mse_in(S[k]), fc * mse_in(C[k]), fl * mse_in(L[k])
            part = {"M": (em, fm), "D": (max(0.0, total - em - es), 1 - fm - fs), "S": (es, fs), "C": (ec, fc),
                    "L": (el, fl), "U": (max(0.0, es - ec), fs - fc)}
            acc["psnr"] += psnr(total)
            acc["mse"] += total
            for r in names:
                e, f = part[r]
                acc["s" + r] += e / total if total > 0 else 0
                acc["f" + r] += f
                acc["w" + r] += psnr(total - e)
        n = len(keys)
        v = {k: a / n for k, a in acc.items()}
        print("%s,%d,%.2f,%.3e," % (m, n, v["psnr"], v["mse"]) + ",".join("%.3f" % v["s" + r] for r in names) + ","
              + ",".join("%.3f" % v["f" + r] for r in names) + "," + ",".join("%.2f" % v["w" + r] for r in names))


def main(argv):
    cmd, args = (argv[1], argv[2:]) if len(argv) > 1 else ("", [])
    pairs = lambda text: [tuple(p.split(":", 1)) for p in text.split(",")] if text else []
    commands = {
        "scenes": (3, 4, lambda a: scenes(a[0], a[1].split(","), a[2].split(","), pairs(a[3] if len(a) > 3 else ""))),
        "scenes-by-row": (3, 4, lambda a: scenes(a[0], a[1].split(","), a[2].split(","),
                                                 pairs(a[3] if len(a) > 3 else ""), True)),
        "upsample-st": (3, 5, lambda a: upsample_st(*a)),
        "tuning": (1, 1, lambda a: tuning(a[0])),
        "tuning-rows": (2, None, lambda a: tuning_rows(a[0], a[1], a[2:])),
        "tuning-region-rows": (2, None, lambda a: tuning_region_rows(a[0], a[1], a[2:])),
        "tuning-regions": (1, 1, lambda a: tuning_regions(a[0])),
        "tuned-variants": (2, None, lambda a: tuned_variants(a[0], a[1].split(","), a[2:])),
        "interval": (3, 3, lambda a: interval(*a)),
        "value": (3, 4, lambda a: value(*a)),
        "paired-rows": (4, 4, lambda a: paired_rows(*a)),
        "region-table": (4, 5, lambda a: region_table(a[0], a[1], a[2].split(","), a[3].split(","),
                                                      pairs(a[4] if len(a) > 4 else ""))),
        "morph-summary": (1, 1, lambda a: morph_summary(a[0])),
        "noise-floor": (4, 4, lambda a: noise_floor(*a)),
        "csv-mean": (2, 3, lambda a: csv_mean(*a)),
        "pass-ms-mean": (1, 2, lambda a: pass_ms_mean(*a)),
        "mean": (0, 1, lambda a: mean(*a)),
        "median-ms": (0, 0, lambda a: median_ms()),
        "per-frame": (2, 3, lambda a: per_frame(*a)),
        "regions": (6, None, lambda a: regions(a[0], a[1], a[2], a[3], a[4], a[5:])),
    }
    if cmd not in commands:
        sys.stderr.write(__doc__)
        return 1
    least, most, run = commands[cmd]
    if len(args) < least or (most is not None and len(args) > most) or (cmd == "upsample-st" and len(args) == 4):
        sys.stderr.write(f"tables.py {cmd}: wrong number of arguments\n" + __doc__)
        return 1
    run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
