#!/usr/bin/env python3
"""An experiment's summary table from compare's JSON files (one per scene): per variant the mean of each metric
with its 95 % interval, the mean compute time from the output headers, whether the variant is on the Pareto front
of compute time against PSNR (compare's `pareto` flag, the front of its speed chart), and its paired PSNR
difference against the baseline with the interval; with compare --regions, a table per scene of the regions'
shares and each variant's mean PSNR [95 % CI] / pooled PSNR per region; with --noise-floor-spp, the reference's
noise floor above each scene's table (from the noise-floor.json files among the inputs, beside each compare.json:
tables.py noise-floor's line). It only formats what compare computed (docs/pipelines.md)."""
import argparse
import contextlib
import io
import json
import os
import sys

# The cells are formatted by pipelines/tables.py, the pipelines' one table formatter.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
from tables import fmt_value as fmt, num, with_ci  # noqa: E402
from tables import noise_floor  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--title", default="")
    ap.add_argument("--baseline", default="")
    ap.add_argument("--out", required=True)
    ap.add_argument("--noise-floor-spp", type=int, default=0,
                    help="samples per pixel of the reference; its noise-floor.json files were rendered at 4x")
    ap.add_argument("json", nargs="+")
    a = ap.parse_args()
    floors = {os.path.dirname(p): p for p in a.json if os.path.basename(p) == "noise-floor.json"}
    lines = [f"# {a.title}", ""]
    for path in a.json:
        if os.path.basename(path) == "noise-floor.json":
            continue
        scene = os.path.basename(os.path.dirname(path))
        report = json.load(open(path))
        seqs = report["sequences"]
        lines += [f"## {scene}", ""]
        floor = floors.get(os.path.dirname(path))
        if floor and a.noise_floor_spp > 0:
            text = io.StringIO()
            with contextlib.redirect_stdout(text):
                noise_floor(floor, path, a.noise_floor_spp, 4 * a.noise_floor_spp)
            lines += [text.getvalue().strip(), ""]
        lines += [
                  "| variant | PSNR dB [95% CI] | SSIM | flicker | compute ms | Pareto | PSNR - " + (a.baseline or "baseline") + " [95% CI] |",
                  "|---|---|---|---|---|---|---|"]
        paired = {}
        for p in report.get("paired", []):
            if p["metric"] != "psnr_rgb" or p.get("region", "all") != "all":  # the whole frame (--regions adds more)
                continue
            if p["b"] == a.baseline:
                paired[p["a"]] = (num(p["mean_difference"]), p["ci95"])
            elif p["a"] == a.baseline:
                ci = p["ci95"]
                paired[p["b"]] = (-num(p["mean_difference"]), [-(num(ci[1]) or 0), -(num(ci[0]) or 0)])
        for s in seqs:
            d = paired.get(s["name"])
            diff = "-" if not d else f"{fmt(d[0])} [{fmt(d[1][0])}, {fmt(d[1][1])}]"
            lines.append(f"| {s['name']} | {with_ci(s.get('psnr_rgb'))} | {with_ci(s.get('ssim'), 4)} | "
                         f"{with_ci(s.get('flicker'), 4)} | {fmt(s.get('compute_ms'), 3)} | "
                         f"{'yes' if s.get('pareto') else ''} | {diff} |")
        # With compare --regions motion: per region its share and each variant's mean PSNR [95% CI] / pooled PSNR.
        if any("regions" in q for q in seqs):
            lines += ["", "| region | share | " + " | ".join(q["name"] for q in seqs) + " |",
                      "|---|---|" + "---|" * len(seqs)]
            for region in ("static", "moving", "disoccluded"):
                rs = [(q.get("regions") or {}).get(region) or {} for q in seqs]
                share = num(rs[0].get("share")) if rs and rs[0] else None
                cells = [("-" if num((r.get("psnr_rgb") or {}).get("mean")) is None else
                          f"{with_ci(r.get('psnr_rgb'))} / {fmt(num((r.get('psnr_rgb_pooled') or {}).get('value')))}")
                         for r in rs]
                lines.append(f"| {region} | {fmt(100.0 * share, 1) + ' %' if share is not None else '-'} | "
                             + " | ".join(cells) + " |")
        plots = os.path.join(os.path.dirname(path), "plots")
        lines += ["", f"Charts: `{os.path.relpath(plots, os.path.dirname(a.out))}/` (metrics-speed.png: compute time "
                      "against PSNR)", ""]
    with open(a.out + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(a.out + ".tmp", a.out)


if __name__ == "__main__":
    main()
