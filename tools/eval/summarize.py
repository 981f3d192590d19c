#!/usr/bin/env python3
"""The issue-25 and issue-26 target tables of an evaluation-corpus run, per half.

    python3 tools/eval/summarize.py --dir build/eval-corpus [--half validation] [--cases COMBO]
    python3 tools/eval/summarize.py --results a.csv [--preview-results b.csv] --corpus FILE

A case is one (scene, spp, combination) with an `ensemble` row. Its best member is the member
of the combination with the least relMSE at that scene and spp. Per half it prints: the share
of cases where the ensemble's relMSE is below its best member's (overall and per spp), the
worst and the geometric mean of ensemble/best-member relMSE, the share where the ensemble's
DSSIM is no worse than the least DSSIM of its members, the shares where it beats one-hot pre,
one-hot post and the average, and the oracle's geometric mean (the headroom); the same for the
--preview sweeps at their spp; and the issue-26 check, each member's relMSE against the noisy
input's per scene and spp. Python 3 standard library only; exit code 2 on bad input.
"""
import argparse
import csv
import glob
import math
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import corpus_file  # noqa: E402

COLUMNS = ("scene", "spp", "method", "combiner", "relmse", "dssim")
TARGETS = {"beats": 90.0, "beats_per_spp": 80.0, "worst": 1.1, "geomean": 0.6, "dssim": 70.0,
           "onehot": 95.0}


def read_rows(path, scene=None):
    """Rows of a sweep CSV as dicts (spp int, relmse/dssim float); `scene` renames every row
    (a corpus entry's sweep names its scene after the file)."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise corpus_file.CorpusError("%s: not a sweep table (no column %s)" %
                                              (path, missing[0]))
            rows = []
            for number, row in enumerate(reader, 2):
                try:
                    rows.append({"scene": scene or row["scene"], "spp": int(row["spp"]),
                                 "method": row["method"], "combiner": row["combiner"],
                                 "relmse": float(row["relmse"]), "dssim": float(row["dssim"])})
                except (TypeError, ValueError):
                    raise corpus_file.CorpusError("%s: line %d: bad number" % (path, number))
            return rows
    except OSError as e:
        raise corpus_file.CorpusError("%s: cannot read (%s)" % (path, e.strerror))


def rows_of_dir(directory, corpus):
    """(main rows, preview rows) of a corpus run: every finished case of every entry."""
    main, preview = [], []
    for entry in corpus["entries"]:
        for suffix, rows in (("", main), (".preview", preview)):
            for path in sorted(glob.glob(os.path.join(directory, entry["name"] + suffix,
                                                      "cases", "*.csv"))):
                rows += read_rows(path, entry["name"])
    return main, preview


class Index:
    """Rows by (scene, spp, method, combiner)."""

    def __init__(self, rows):
        self.rows = {}
        for r in rows:
            self.rows[(r["scene"], r["spp"], r["method"], r["combiner"])] = r

    def get(self, scene, spp, method, combiner="-"):
        return self.rows.get((scene, spp, method, combiner))


def ensemble_cases(rows):
    """One dict per (scene, spp, combination) with an ensemble row and all its members."""
    index = Index(rows)
    cases = []
    for r in rows:
        if r["combiner"] != "ensemble":
            continue
        members = [index.get(r["scene"], r["spp"], m) for m in r["method"].split("+")]
        if any(m is None for m in members):
            continue
        best = min(members, key=lambda m: (not math.isfinite(m["relmse"]), m["relmse"]))
        case = {"scene": r["scene"], "spp": r["spp"], "combo": r["method"],
                "ensemble": r["relmse"], "ensemble_dssim": r["dssim"],
                "best": best["relmse"], "best_name": best["method"],
                "best_dssim": min(m["dssim"] for m in members)}
        for other in ("onehot-pre", "onehot-post", "average", "oracle"):
            o = index.get(r["scene"], r["spp"], r["method"], other)
            case[other] = o["relmse"] if o else None
        cases.append(case)
    return cases


def ratio(case):
    e, b = case["ensemble"], case["best"]
    if not math.isfinite(e) or e < 0:
        return math.inf
    if not math.isfinite(b) or b <= 0:
        return 1.0 if e == b else (0.0 if math.isfinite(e) and not math.isfinite(b) else math.inf)
    return e / b


def percent(count, total):
    return 100.0 * count / total if total else float("nan")


def geomean(values):
    values = list(values)
    if not values:
        return float("nan")
    if any(v <= 0 or not math.isfinite(v) for v in values):
        return math.inf if any(not math.isfinite(v) for v in values) else 0.0
    return math.exp(sum(math.log(v) for v in values) / len(values))


def metrics(cases):
    """The targets' figures over a list of cases (see the module comment)."""
    n = len(cases)
    out = {"cases": n}
    if not n:
        return out
    ratios = [ratio(c) for c in cases]
    out["beats"] = percent(sum(c["ensemble"] < c["best"] for c in cases), n)
    out["per_spp"] = {}
    for spp in sorted({c["spp"] for c in cases}):
        sub = [c for c in cases if c["spp"] == spp]
        out["per_spp"][spp] = (percent(sum(c["ensemble"] < c["best"] for c in sub), len(sub)),
                               len(sub))
    worst = max(range(n), key=lambda i: ratios[i])
    out["worst"] = ratios[worst]
    out["worst_case"] = "%s %d spp %s" % (cases[worst]["scene"], cases[worst]["spp"],
                                          cases[worst]["combo"])
    out["geomean"] = geomean(ratios)
    out["dssim"] = percent(sum(c["ensemble_dssim"] <= c["best_dssim"] for c in cases), n)
    for other in ("onehot-pre", "onehot-post", "average"):
        having = [c for c in cases if c[other] is not None]
        out[other] = (percent(sum(c["ensemble"] < c[other] for c in having), len(having))
                      if having else None)
    oracle = [c for c in cases if c["oracle"] is not None]
    out["oracle_geomean"] = (geomean(ratio(dict(c, ensemble=c["oracle"])) for c in oracle)
                             if oracle else None)
    return out


def mark(ok):
    return "" if ok is None else (" ✓" if ok else " ✗")


def fmt_pct(value):
    return "–" if value is None or value != value else "%.1f %%" % value


def metric_lines(m, per_spp=True):
    """Markdown table rows (figure | value) for one set of cases."""
    if not m["cases"]:
        return ["| cases | 0 |"]
    lines = ["| cases (scene, spp, combination) | %d |" % m["cases"],
             "| ensemble beats its best member (relMSE) | %s%s |" % (
                 fmt_pct(m["beats"]), mark(m["beats"] >= TARGETS["beats"]))]
    if per_spp:
        for spp, (value, count) in m["per_spp"].items():
            lines.append("| … at %d spp (%d cases) | %s%s |" % (
                spp, count, fmt_pct(value), mark(value >= TARGETS["beats_per_spp"])))
    lines += [
        "| worst ensemble / best member | %.3f (%s)%s |" % (
            m["worst"], m["worst_case"], mark(m["worst"] <= TARGETS["worst"])),
        "| geometric mean ensemble / best member | %.3f%s |" % (
            m["geomean"], mark(m["geomean"] <= TARGETS["geomean"])),
        "| DSSIM no worse than the best member's | %s%s |" % (
            fmt_pct(m["dssim"]), mark(m["dssim"] >= TARGETS["dssim"])),
        "| beats one-hot pre | %s%s |" % (
            fmt_pct(m["onehot-pre"]),
            mark(None if m["onehot-pre"] is None else m["onehot-pre"] >= TARGETS["onehot"])),
        "| beats one-hot post | %s%s |" % (
            fmt_pct(m["onehot-post"]),
            mark(None if m["onehot-post"] is None else m["onehot-post"] >= TARGETS["onehot"])),
        "| beats the average | %s |" % fmt_pct(m["average"]),
    ]
    if m.get("oracle_geomean") is not None:
        lines.append("| geometric mean oracle / best member (headroom) | %.3f |" %
                     m["oracle_geomean"])
    return lines


def member_vs_noisy(rows):
    """Issue 26: per (scene, spp), the noisy relMSE and each single member's ratio to it."""
    index = Index(rows)
    table = []
    for (scene, spp) in sorted({(r["scene"], r["spp"]) for r in rows}):
        noisy = index.get(scene, spp, "noisy")
        if noisy is None:
            continue
        members = sorted({r["method"] for r in rows if r["scene"] == scene and r["spp"] == spp
                          and r["combiner"] == "-" and r["method"] != "noisy"})
        ratios = {}
        for m in members:
            v = index.get(scene, spp, m)["relmse"]
            ratios[m] = v / noisy["relmse"] if noisy["relmse"] > 0 else math.inf
        table.append({"scene": scene, "spp": spp, "noisy": noisy["relmse"], "ratios": ratios})
    return table


def print_member_check(table, out):
    methods = sorted({m for row in table for m in row["ratios"]})
    worse = [(row["scene"], row["spp"], m, r) for row in table for m, r in row["ratios"].items()
             if not r <= 1.0]
    total = sum(len(row["ratios"]) for row in table)
    if not table:
        out.write("\nIssue 26: no member rows\n")
        return
    out.write("\nIssue 26: member relMSE / noisy relMSE (target ≤ 1 everywhere): %d of %d "
              "(scene, spp, member) worse than the noisy input\n\n" % (len(worse), total))
    out.write("| member | (scene, spp) worse than noisy | worst member / noisy |\n|---|---|---|\n")
    for m in methods:
        mine = [(row["ratios"][m], row["scene"], row["spp"]) for row in table if m in row["ratios"]]
        bad = sum(1 for r, _, _ in mine if not r <= 1.0)
        worst = max(mine, key=lambda t: (not t[0] <= math.inf, t[0]))
        out.write("| %s | %d of %d | %.3g (%s %d spp) |\n" % (m, bad, len(mine), *worst))
    out.write("\n| scene | spp | noisy relMSE | " + " | ".join(methods) + " |\n")
    out.write("|---|---|---|" + "---|" * len(methods) + "\n")
    for row in table:
        cells = []
        for m in methods:
            r = row["ratios"].get(m)
            cells.append("–" if r is None else ("**%.3g**" % r if not r <= 1.0 else "%.3g" % r))
        out.write("| %s | %d | %.4g | %s |\n" % (row["scene"], row["spp"], row["noisy"],
                                                 " | ".join(cells)))


def print_per_combination(cases, combos, out):
    out.write("\nPer combination\n\n| combination | cases | beats best member | geometric mean "
              "| worst | DSSIM no worse | beats one-hot pre / post |\n"
              "|---|---|---|---|---|---|---|\n")
    for combo in combos:
        m = metrics([c for c in cases if c["combo"] == combo])
        out.write("| %s | %d | %s | %.3f | %.3f | %s | %s / %s |\n" % (
            combo, m["cases"], fmt_pct(m["beats"]), m["geomean"], m["worst"],
            fmt_pct(m["dssim"]), fmt_pct(m["onehot-pre"]), fmt_pct(m["onehot-post"])))


def print_cases(cases, combo, out):
    chosen = [c for c in cases if c["combo"] == combo]
    out.write("\nPer scene and spp, %s (relMSE; ratio = ensemble / best member; DSSIM: the "
              "least of the members' and the ensemble's)\n\n" % combo)
    out.write("| scene | spp | best member | its relMSE | ensemble | ratio | members' DSSIM | "
              "ensemble DSSIM | one-hot pre | one-hot post | oracle |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|\n")
    for c in sorted(chosen, key=lambda c: (c["scene"], c["spp"])):
        out.write("| %s | %d | %s | %.4g | %.4g | %.3f | %.4f | %.4f | %s | %s | %s |\n" % (
            c["scene"], c["spp"], c["best_name"], c["best"], c["ensemble"], ratio(c),
            c["best_dssim"], c["ensemble_dssim"],
            *("%.4g" % c[k] if c[k] is not None else "–"
              for k in ("onehot-pre", "onehot-post", "oracle"))))


def summarize(main_rows, preview_rows, halves, half_of, cases_combos, out):
    for half in halves:
        in_half = lambda rows: [r for r in rows if half_of.get(r["scene"]) == half]  # noqa: E731
        rows, preview = in_half(main_rows), in_half(preview_rows)
        scenes = sorted({r["scene"] for r in rows})
        out.write("\n## %s half: %d scene(s)\n\n" % (half, len(scenes)))
        cases = ensemble_cases(rows)
        out.write("| figure (all combinations) | value |\n|---|---|\n")
        out.write("\n".join(metric_lines(metrics(cases))) + "\n")
        combos = sorted({c["combo"] for c in cases}, key=lambda s: (s.count("+"), s))
        if combos:
            print_per_combination(cases, combos, out)
        for combo in combos:
            if combo in cases_combos:
                print_cases(cases, combo, out)
        if preview:
            pcases = ensemble_cases(preview)
            out.write("\n`--preview` (two à-trous members, no weight filter), spp %s\n\n" %
                      ",".join(str(s) for s in sorted({c["spp"] for c in pcases})))
            out.write("| figure | value |\n|---|---|\n")
            out.write("\n".join(metric_lines(metrics(pcases), per_spp=False)) + "\n")
            if "preview" in cases_combos:
                for combo in sorted({c["combo"] for c in pcases}):
                    print_cases(pcases, combo, out)
        print_member_check(member_vs_noisy(rows), out)


def brief_line(label, half, main_rows, preview_rows, half_of):
    """One line of the headline figures of a half (for comparing many variants)."""
    rows = [r for r in main_rows if half_of.get(r["scene"]) == half]
    preview = [r for r in preview_rows if half_of.get(r["scene"]) == half]
    m = metrics(ensemble_cases(rows))
    if not m["cases"]:
        return "%s %s: no cases" % (label, half)
    text = "%s %s: %d cases, beats %.1f%% (%s), worst %.2f, geo %.3f, dssim %.0f%%, " \
           "pre %.0f%% post %.0f%% avg %.0f%%" % (
               label, half, m["cases"], m["beats"],
               " ".join("%.0f" % v for v, _ in m["per_spp"].values()), m["worst"], m["geomean"],
               m["dssim"], m["onehot-pre"] or 0, m["onehot-post"] or 0, m["average"] or 0)
    p = metrics(ensemble_cases(preview))
    if p["cases"]:
        text += " | preview beats %.0f%% worst %.2f geo %.3f dssim %.0f%%" % (
            p["beats"], p["worst"], p["geomean"], p["dssim"])
    return text


def print_timings(directory, out):
    path = os.path.join(directory, "timings.tsv")
    if not os.path.exists(path):
        return
    total = defaultdict(float)
    with open(path, encoding="utf-8") as f:
        for line in f:
            fields = line.rstrip("\n").split("\t")
            if len(fields) >= 3:
                total[fields[1]] += float(fields[2])
    out.write("\nRun time (timings.tsv, summed over runs): %s; total %.1f min\n" % (
        ", ".join("%s %.1f min" % (k, v / 60) for k, v in sorted(total.items())),
        sum(total.values()) / 60))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--corpus", default=corpus_file.DEFAULT_CORPUS)
    parser.add_argument("--dir", help="a corpus.py output folder")
    parser.add_argument("--results", action="append", default=[],
                        help="a sweep CSV whose scene column holds corpus entry names (repeatable)")
    parser.add_argument("--preview-results", action="append", default=[],
                        help="a sweep CSV of the --preview configuration (repeatable)")
    parser.add_argument("--half", choices=("both", "tuning", "validation"), default="both")
    parser.add_argument("--cases", action="append", default=[], metavar="COMBO",
                        help="also print the per scene/spp table of this combination, e.g. "
                        "nfor+rdfc+atrous, or 'preview' (repeatable)")
    parser.add_argument("--brief", action="store_true",
                        help="one line of headline figures per half (comparing variants)")
    parser.add_argument("--label", default="", help="the --brief line's label")
    args = parser.parse_args(argv)
    try:
        if bool(args.dir) == bool(args.results):
            raise corpus_file.CorpusError("give either --dir or --results")
        corpus = corpus_file.load(args.corpus)
        if args.dir:
            if not os.path.isdir(args.dir):
                raise corpus_file.CorpusError("--dir: %s is not a folder" % args.dir)
            main_rows, preview_rows = rows_of_dir(args.dir, corpus)
        else:
            main_rows = [r for p in args.results for r in read_rows(p)]
            preview_rows = [r for p in args.preview_results for r in read_rows(p)]
        half_of = corpus_file.half_of(corpus)
        unknown = sorted({r["scene"] for r in main_rows + preview_rows} - set(half_of))
        if unknown:
            raise corpus_file.CorpusError("scene '%s' of the results is not a corpus entry" %
                                          unknown[0])
    except corpus_file.CorpusError as e:
        print("summarize: %s" % e, file=sys.stderr)
        return 2
    halves = corpus_file.HALVES if args.half == "both" else (args.half,)
    if args.brief:
        for half in halves:
            print(brief_line(args.label, half, main_rows, preview_rows, half_of))
        return 0
    summarize(main_rows, preview_rows, halves, half_of, set(args.cases), sys.stdout)
    if args.dir:
        print_timings(args.dir, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
