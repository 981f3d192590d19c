#!/usr/bin/env python3
"""The real `chorus render --preview` (K = 2, the halves estimate, its two a-trous members) on
every rendered entry of the evaluation corpus, several seeds, against the references of a
cached corpus (tools/eval/cached_corpus.py). The cached corpus combines the preview members from
K = 4 renders, which is not what a preview runs; this is. Extra flags after `--` go to every
render (e.g. `-- --splits 4`). Prints one line per render and the per-half summary.
With `--against "FLAGS"` every render also runs without `--preview`, with FLAGS (e.g.
`--against "--denoise nfor,rdfc,atrous"`, the default job), and the summary gives the preview's
relMSE over that run's. With `--baseline DIR` (the --out of an earlier run, e.g. with other flags
or another binary) the summary also gives the preview's relMSE over that run's preview, render by
render."""
import argparse
import json
import math
import os
import subprocess
import sys

import corpus_file
from corpus import Paths, scene_flags


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--corpus", default=corpus_file.DEFAULT_CORPUS)
    parser.add_argument("--cache", default="build/eval-cache")
    parser.add_argument("--chorus", default="build/chorus")
    parser.add_argument("--out", required=True)
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--shared", default=os.environ.get("CHORUS_SHARED_DIR", "../shared"))
    parser.add_argument("--against", help="flags of a run without --preview to compare with")
    parser.add_argument("--baseline", help="an earlier run's --out to compare the previews with")
    parser.add_argument("flags", nargs="*")
    args = parser.parse_args()
    corpus = json.load(open(args.corpus))
    # The cache keeps the generated scenes in CACHE/scenes, as cached_corpus.py does.
    paths = Paths(argparse.Namespace(out=args.out, shared=args.shared,
                                     scenes=os.path.join(args.cache, "scenes")))
    rows = []
    for entry in corpus["entries"]:
        if entry["source"] == "synthetic":
            continue
        for seed in args.seeds.split(","):
            def render(name, flags):
                out = os.path.join(args.out, "%s-%s%s" % (entry["name"], seed, name))
                command = [args.chorus, "render", paths.resolve(entry["scene"], entry["name"]),
                           "--seed", seed,
                           "--reference", os.path.join(args.cache, entry["name"], "reference.exr"),
                           "--out", out, "--quiet", "--threads", "2"] + \
                    scene_flags(entry, paths) + flags + args.flags
                subprocess.run(command, check=True, stderr=subprocess.DEVNULL)
                return json.load(open(os.path.join(out, "stats.json")))["metrics"]
            metrics = render("", ["--preview"])
            members = [v for k, v in metrics.items() if k not in ("noisy", "denoised")]
            best = min(m["relmse"] for m in members)
            against = render("-against", args.against.split())["denoised"]["relmse"] \
                if args.against else None
            baseline = json.load(open(os.path.join(
                args.baseline, "%s-%s" % (entry["name"], seed), "stats.json"))
            )["metrics"]["denoised"]["relmse"] if args.baseline else None
            row = (entry["name"], entry["half"], seed, metrics["denoised"]["relmse"], best,
                   metrics["denoised"]["dssim"] <= min(m["dssim"] for m in members), against,
                   baseline)
            rows.append(row)
            print("%-28s %-10s seed %s preview %.4g best member %.4g ratio %.3f" % (
                row[:5] + (row[3] / best,)) +
                (" against %.4g ratio %.3f" % (against, row[3] / against) if against else ""),
                flush=True)
    geometric = lambda ratios: math.exp(sum(map(math.log, ratios)) / len(ratios))
    for half in ("tuning", "validation"):
        cases = [r for r in rows if r[1] == half]
        ratios = [r[3] / r[4] for r in cases]
        print("%s: %d renders, beats its best member %.0f%%, geometric mean %.3f, worst %.2f, "
              "DSSIM no worse %.0f%%" % (
                  half, len(cases), 100.0 * sum(q < 1 for q in ratios) / len(cases),
                  geometric(ratios), max(ratios),
                  100.0 * sum(r[5] for r in cases) / len(cases)))
        for column, name in ((6, "against"), (7, "baseline")):
            if cases and cases[0][column] is not None:
                ratios = [r[3] / r[column] for r in cases]
                worst = max(cases, key=lambda r: r[3] / r[column])
                print("%s: preview / %s: geometric mean %.3f, better in %d of %d, worst %.3f "
                      "(%s seed %s)" % (half, name, geometric(ratios), sum(q < 1 for q in ratios),
                                        len(ratios), max(ratios), worst[0], worst[2]))


if __name__ == "__main__":
    sys.exit(main())
