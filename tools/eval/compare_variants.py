#!/usr/bin/env python3
"""Compares combine-only variants (tools/eval/cached_corpus.py combine) case by case on one half:
per variant the headline figures, how many cases it wins or loses against the first variant
(relMSE, by more than 1 %), and, over all the listed variants, the figures of choosing per case
(or per image: scene and spp, all combinations alike) the variant with the least true relMSE:
the most that choosing among them per image could give.

    python3 tools/eval/compare_variants.py --cache build/eval-cache --half tuning base v1 v2

A variant is a name under CACHE/variants/ or the path of a variant folder (to compare variants
of two caches, e.g. before and after a member change). "vs FIRST" also gives the geometric
mean of the ensemble's relMSE over the first variant's, case by case.

Python 3 standard library only; exit code 2 on bad input.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import corpus_file  # noqa: E402
import summarize  # noqa: E402


def cases_of(directory, corpus, half):
    main, _ = summarize.rows_of_dir(directory, corpus)
    half_of = corpus_file.half_of(corpus)
    rows = [r for r in main if half_of.get(r["scene"]) == half]
    return {(c["scene"], c["spp"], c["combo"]): c for c in summarize.ensemble_cases(rows)}


def line(label, cases):
    m = summarize.metrics(list(cases))
    return "%-28s beats %5.1f%% (%s) worst %6.2f geo %.3f dssim %3.0f%%" % (
        label, m["beats"], " ".join("%3.0f" % v for v, _ in m["per_spp"].values()), m["worst"],
        m["geomean"], m["dssim"])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cache", default=os.path.join(corpus_file.REPOSITORY, "build",
                                                       "eval-cache"))
    parser.add_argument("--corpus", default=corpus_file.DEFAULT_CORPUS)
    parser.add_argument("--half", choices=corpus_file.HALVES, default="tuning")
    parser.add_argument("variants", nargs="+")
    args = parser.parse_args(argv)
    try:
        corpus = corpus_file.load(args.corpus)
        tables = {}
        for v in args.variants:
            folder = v if os.path.isdir(v) else os.path.join(args.cache, "variants", v)
            if not os.path.isdir(folder):
                raise corpus_file.CorpusError("%s: no such variant folder" % folder)
            tables[v] = cases_of(folder, corpus, args.half)
    except corpus_file.CorpusError as e:
        print("compare_variants: %s" % e, file=sys.stderr)
        return 2
    first = tables[args.variants[0]]
    keys = sorted(set.intersection(*(set(t) for t in tables.values())))
    for v in args.variants:
        t = tables[v]
        wins = sum(t[k]["ensemble"] < 0.99 * first[k]["ensemble"] for k in keys)
        losses = sum(t[k]["ensemble"] > 1.01 * first[k]["ensemble"] for k in keys)
        ratio = math.exp(sum(math.log(t[k]["ensemble"] / first[k]["ensemble"]) for k in keys
                             if t[k]["ensemble"] > 0 and first[k]["ensemble"] > 0) / len(keys))
        print(line(v, (t[k] for k in keys)) + "  vs %s: +%d -%d, geo %.4f" % (
            args.variants[0], wins, losses, ratio))
    best_case = [min((tables[v][k] for v in args.variants), key=lambda c: c["ensemble"])
                 for k in keys]
    print(line("best variant per case", best_case))
    images = sorted({(k[0], k[1]) for k in keys})
    per_image = []
    for image in images:
        mine = [k for k in keys if (k[0], k[1]) == image]
        score = lambda v: sum(tables[v][k]["ensemble"] / tables[v][k]["best"] for k in mine)  # noqa
        chosen = min(args.variants, key=score)
        per_image += [tables[chosen][k] for k in mine]
    print(line("best variant per image", per_image))
    return 0


if __name__ == "__main__":
    sys.exit(main())
