#!/usr/bin/env python3
"""Keeps the evaluation-corpus tools (tools/eval/) honest and fast: the split file, the
generated scenes, corpus.py's selection, summarize.py's figures on a hand-made table with known
answers, and the synthetic entries' program. Run by CTest (tests/CMakeLists.txt) with
CHORUS_BINARY and SYNTHETIC_CORPUS naming the built programs."""
import csv
import filecmp
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

REPOSITORY = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
EVAL = os.path.join(REPOSITORY, "tools", "eval")
sys.path.insert(0, EVAL)
import corpus_file  # noqa: E402
import summarize  # noqa: E402

CHORUS = os.environ.get("CHORUS_BINARY", os.path.join(REPOSITORY, "build", "chorus"))
SYNTHETIC = os.environ.get("SYNTHETIC_CORPUS",
                           os.path.join(REPOSITORY, "build", "eval", "synthetic_corpus"))


def shared_dir():
    candidate = os.environ.get("CHORUS_SHARED_DIR") or os.path.join(
        os.path.dirname(REPOSITORY), "shared")
    return candidate if os.path.isdir(candidate) else None


def run(*argv):
    return subprocess.run(list(argv), capture_output=True, text=True)


class SplitFile(unittest.TestCase):
    def setUp(self):
        self.corpus = corpus_file.load()
        self.entries = self.corpus["entries"]

    def scene_key(self, e):
        return "synthetic:" + e["synthetic"]["scene"] if e["source"] == "synthetic" else e["scene"]

    def test_at_least_twelve_scenes_in_two_disjoint_halves(self):
        self.assertGreaterEqual(len({self.scene_key(e) for e in self.entries}), 12)
        halves = {h: {self.scene_key(e) for e in self.entries if e["half"] == h}
                  for h in corpus_file.HALVES}
        self.assertTrue(halves["tuning"] and halves["validation"])
        self.assertEqual(halves["tuning"] & halves["validation"], set())

    def test_each_half_mixes_kinds_of_scene(self):
        for half in corpus_file.HALVES:
            entries = [e for e in self.entries if e["half"] == half]
            tags = {t for e in entries for t in e["tags"]}
            for tag in ("interior", "exterior", "env-lit", "glass", "glossy", "textured",
                        "synthetic"):
                self.assertIn(tag, tags, "%s half has no %s scene" % (half, tag))
            self.assertEqual({e["source"] for e in entries}, set(corpus_file.SOURCES), half)
            self.assertTrue(any(e["source"] != "synthetic" and not e.get("env") for e in entries),
                            "%s half has no scene without an environment map" % half)

    def test_sample_counts_and_sizes(self):
        self.assertEqual(self.corpus["spp"], [4, 8, 16, 64, 256])
        for e in self.entries:
            size = e["synthetic"]["size"] if e["source"] == "synthetic" else e["width"]
            self.assertTrue(128 <= size <= 256, e["name"])
            if e["source"] != "synthetic":
                self.assertTrue(2048 <= e["reference_spp"] <= 4096, e["name"])

    def test_project_scenes_exist_and_every_shared_scene_is_used(self):
        used = {e["scene"] for e in self.entries if e["source"] != "synthetic"}
        for scene in used:
            if scene.startswith("project:"):
                self.assertTrue(os.path.isfile(os.path.join(REPOSITORY, scene[8:])), scene)
        shared = shared_dir()
        if shared is None:
            self.skipTest("no shared folder")
        folders = [d for d in os.listdir(os.path.join(shared, "scenes"))
                   if not d.startswith("_") and os.path.isdir(os.path.join(shared, "scenes", d))]
        for folder in folders:
            self.assertTrue(any(s.startswith("shared:%s/" % folder) for s in used), folder)
        for e in self.entries:
            for key in ("scene", "env"):
                if e.get(key, "").startswith("shared:"):
                    self.assertTrue(os.path.isfile(os.path.join(shared, "scenes", e[key][7:])),
                                    e[key])

    def test_docs_table_lists_the_same_split(self):
        with open(os.path.join(REPOSITORY, "docs", "evaluation.md"), encoding="utf-8") as f:
            text = f.read()
        # The first table after the heading: one row per entry, its name and half first.
        section = text[text.index("## The corpus and its split"):]
        rows = section[section.index("\n|") + 1:].split("\n\n")[0].splitlines()[2:]
        halves = {r.split("|")[1].strip(): r.split("|")[2].strip() for r in rows}
        self.assertEqual(halves, corpus_file.half_of(self.corpus))

    def test_large_image_corpora_keep_the_split(self):
        # corpus-256.json and corpus-512.json re-render entries of this corpus at the default
        # job's sizes: each entry the same scene, environment and lens in the same half, both
        # halves represented, so that what they decide is still tuned on one half only.
        main = {e["name"]: e for e in self.entries}
        for width in (256, 512):
            large = corpus_file.load(os.path.join(EVAL, "corpus-%d.json" % width))
            self.assertEqual({e["half"] for e in large["entries"]}, set(corpus_file.HALVES))
            for e in large["entries"]:
                self.assertIn(e["name"], main)
                for key in ("half", "source", "scene", "env", "lens"):
                    self.assertEqual(e.get(key), main[e["name"]].get(key), (width, e["name"], key))
                self.assertEqual(e["width"], width, e["name"])

    def write_corpus(self, directory, entries):
        path = os.path.join(directory, "corpus.json")
        with open(path, "w") as f:
            json.dump(dict(self.corpus, entries=entries), f)
        return path

    def test_checker_rejects_a_scene_in_both_halves_and_a_name_used_twice(self):
        with tempfile.TemporaryDirectory() as tmp:
            first = dict(self.entries[0])
            moved = dict(first, name="moved", half="validation" if first["half"] == "tuning"
                         else "tuning")
            with self.assertRaisesRegex(corpus_file.CorpusError, "split by scene"):
                corpus_file.load(self.write_corpus(tmp, [first, moved]))
            with self.assertRaisesRegex(corpus_file.CorpusError, "name used twice"):
                corpus_file.load(self.write_corpus(tmp, [first, first]))


class GeneratedScenes(unittest.TestCase):
    def test_generated_scenes_are_deterministic_and_load(self):
        corpus = corpus_file.load()
        generator = os.path.join(EVAL, "generate_corpus_scenes.py")
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            for directory in (a, b):
                result = run(sys.executable, generator, directory)
                self.assertEqual(result.returncode, 0, result.stderr)
            files = sorted(os.listdir(a))
            self.assertEqual(files, sorted(os.listdir(b)))
            self.assertEqual(filecmp.cmpfiles(a, b, files, shallow=False)[0], files)
            # Every generated entry is written, and every written scene loads (the corpus's and
            # the fresh set's, docs/evaluation.md).
            for e in corpus["entries"]:
                if e["source"] == "generated":
                    self.assertIn(e["scene"][len("generated:"):], files)
            for name in files:
                info = run(CHORUS, "info", os.path.join(a, name))
                self.assertEqual(info.returncode, 0, info.stderr)
                self.assertIn("triangles", info.stdout)


class CorpusCommand(unittest.TestCase):
    def dry_run(self, *flags):
        result = run(sys.executable, os.path.join(EVAL, "corpus.py"), "--dry-run",
                     "--shared", shared_dir() or REPOSITORY, *flags)
        self.assertEqual(result.returncode, 0, result.stderr)
        return [line.split()[1] for line in result.stdout.splitlines()
                if line.startswith("# ")]

    def test_shards_partition_the_entries(self):
        names = [e["name"] for e in corpus_file.load()["entries"]]
        shards = [set(self.dry_run("--shard", "%d/3" % i)) for i in range(3)]
        self.assertEqual(set().union(*shards), set(names))
        self.assertEqual(sum(len(s) for s in shards), len(names))

    def test_half_selects_its_entries_with_a_preview_sweep_each(self):
        corpus = corpus_file.load()
        validation = {e["name"] for e in corpus["entries"] if e["half"] == "validation"}
        listed = self.dry_run("--half", "validation")
        self.assertEqual(set(listed), validation)
        rendered = [e["name"] for e in corpus["entries"]
                    if e["half"] == "validation" and e["source"] != "synthetic"]
        for name in rendered:
            self.assertEqual(listed.count(name), 2, name)  # the sweep and the preview

    def test_an_entry_with_a_lens_renders_through_it(self):
        # The sweep and the preview sweep both get the lens, so that renders match references.
        result = run(sys.executable, os.path.join(EVAL, "corpus.py"), "--dry-run", "--shared",
                     shared_dir() or REPOSITORY, "--only", "glass-and-metal-dof,glass-and-metal")
        commands = [line for line in result.stdout.splitlines() if not line.startswith("#")]
        with_lens = [c for c in commands if "--lens-radius 0.08 --focus-distance 0" in c]
        self.assertEqual(len(commands), 4, result.stdout)
        self.assertEqual(len(with_lens), 2, result.stdout)
        self.assertTrue(all("glass-and-metal-dof" in c for c in with_lens))

    def test_bad_flags_exit_2_with_one_line(self):
        for flags in (["--shard", "3/3"], ["--only", "no-such-entry"], ["--spp", "4,x"]):
            result = run(sys.executable, os.path.join(EVAL, "corpus.py"), "--dry-run", *flags)
            self.assertEqual(result.returncode, 2, flags)
            self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)


HEADER = "scene,spp,method,combiner,members,relmse,dssim,psnr,smape,render_s,denoise_s,total_s"


def table(rows):
    """rows: (scene, spp, method, combiner, relmse, dssim)."""
    lines = [HEADER] + ["%s,%d,%s,%s,0,%r,%r,0,0,0,0,0" % r for r in rows]
    return "\n".join(lines) + "\n"


# Scene t (tuning), members a, b, c, combination a+b:
#   4 spp: a 0.10, b 0.20 -> best a 0.10; ensemble 0.08 (ratio 0.8, wins); one-hot pre 0.10
#          (beaten), post 0.09 (beaten); DSSIM 0.10 vs members' least 0.12 (no worse)
#  16 spp: a 0.05, b 0.04 -> best b 0.04; ensemble 0.05 (ratio 1.25, loses); pre 0.04 (not
#          beaten), post 0.06 (beaten); DSSIM 0.20 vs 0.15 (worse)
#   c (0.01) is far better but not in a+b: it must not count as the best member.
#   Members vs noisy (0.5 and 0.06): at 16 spp c 0.07 > 0.06 is the one member worse.
# Scene v (validation), 4 spp: best a 0.10, ensemble 0.05 (ratio 0.5).
KNOWN = [
    ("t", 4, "noisy", "-", 0.5, 0.5), ("t", 4, "a", "-", 0.10, 0.12),
    ("t", 4, "b", "-", 0.20, 0.13), ("t", 4, "c", "-", 0.01, 0.01),
    ("t", 4, "a+b", "ensemble", 0.08, 0.10), ("t", 4, "a+b", "onehot-pre", 0.10, 0.1),
    ("t", 4, "a+b", "onehot-post", 0.09, 0.1), ("t", 4, "a+b", "average", 0.15, 0.1),
    ("t", 4, "a+b", "oracle", 0.05, 0.1),
    ("t", 16, "noisy", "-", 0.06, 0.5), ("t", 16, "a", "-", 0.05, 0.15),
    ("t", 16, "b", "-", 0.04, 0.16), ("t", 16, "c", "-", 0.07, 0.01),
    ("t", 16, "a+b", "ensemble", 0.05, 0.20), ("t", 16, "a+b", "onehot-pre", 0.04, 0.1),
    ("t", 16, "a+b", "onehot-post", 0.06, 0.1), ("t", 16, "a+b", "average", 0.045, 0.1),
    ("t", 16, "a+b", "oracle", 0.02, 0.1),
    ("v", 4, "noisy", "-", 1.0, 0.5), ("v", 4, "a", "-", 0.10, 0.2), ("v", 4, "b", "-", 0.3, 0.2),
    ("v", 4, "a+b", "ensemble", 0.05, 0.1),
]


class Summary(unittest.TestCase):
    def rows(self, scene):
        return [{"scene": r[0], "spp": r[1], "method": r[2], "combiner": r[3], "relmse": r[4],
                 "dssim": r[5]} for r in KNOWN if r[0] == scene]

    def test_figures_of_a_hand_made_table(self):
        m = summarize.metrics(summarize.ensemble_cases(self.rows("t")))
        self.assertEqual(m["cases"], 2)
        self.assertAlmostEqual(m["beats"], 50.0)
        self.assertEqual(m["per_spp"], {4: (100.0, 1), 16: (0.0, 1)})
        self.assertAlmostEqual(m["worst"], 1.25)
        self.assertEqual(m["worst_case"], "t 16 spp a+b")
        self.assertAlmostEqual(m["geomean"], math.sqrt(0.8 * 1.25))
        self.assertAlmostEqual(m["dssim"], 50.0)
        self.assertAlmostEqual(m["onehot-pre"], 50.0)
        self.assertAlmostEqual(m["onehot-post"], 100.0)
        self.assertAlmostEqual(m["average"], 50.0)  # 0.08 < 0.15, 0.05 > 0.045
        self.assertAlmostEqual(m["oracle_geomean"], math.sqrt(0.5 * 0.5))

    def test_members_against_the_noisy_input(self):
        check = summarize.member_vs_noisy(self.rows("t"))
        self.assertEqual([(c["scene"], c["spp"]) for c in check], [("t", 4), ("t", 16)])
        self.assertAlmostEqual(check[0]["ratios"]["b"], 0.4)
        worse = [(c["spp"], m) for c in check for m, r in c["ratios"].items() if r > 1]
        self.assertEqual(worse, [(16, "c")])

    def test_command_reads_tables_and_splits_by_half(self):
        with tempfile.TemporaryDirectory() as tmp:
            corpus = {"spp": [4], "methods": "a,b", "combos": "a+b", "combiners": "ensemble",
                      "entries": [
                          {"name": "t", "half": "tuning", "source": "synthetic",
                           "synthetic": {"scene": "x", "size": 8}},
                          {"name": "v", "half": "validation", "source": "synthetic",
                           "synthetic": {"scene": "y", "size": 8}}]}
            corpus_path = os.path.join(tmp, "corpus.json")
            with open(corpus_path, "w") as f:
                json.dump(corpus, f)
            results = os.path.join(tmp, "results.csv")
            with open(results, "w") as f:
                f.write(table(KNOWN))
            script = os.path.join(EVAL, "summarize.py")
            result = run(sys.executable, script, "--corpus", corpus_path, "--results", results,
                         "--half", "validation")
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("| cases (scene, spp, combination) | 1 |", result.stdout)
            self.assertIn("| ensemble beats its best member (relMSE) | 100.0 % ✓ |", result.stdout)
            self.assertIn("| geometric mean ensemble / best member | 0.500 ✓ |", result.stdout)
            self.assertNotIn("tuning half", result.stdout)
            # A scene that is not a corpus entry is bad input.
            with open(results, "a") as f:
                f.write("w,4,noisy,-,0,1,1,0,0,0,0,0\n")
            result = run(sys.executable, script, "--corpus", corpus_path, "--results", results)
            self.assertEqual(result.returncode, 2)
            self.assertIn("'w'", result.stderr)


class SyntheticEntries(unittest.TestCase):
    def test_rows_resume_and_settings(self):
        with tempfile.TemporaryDirectory() as tmp:
            argv = [SYNTHETIC, "--name", "s", "--scene", "shadows", "--size", "32", "--spp", "8",
                    "--threads", "1", "--out", tmp]
            result = run(*argv)
            self.assertEqual(result.returncode, 0, result.stderr)
            case = os.path.join(tmp, "cases", "s_spp8.csv")
            with open(case) as f:
                rows = list(csv.DictReader(f))
            # noisy, three members, four combinations × five combiners.
            self.assertEqual(len(rows), 1 + 3 + 4 * 5)
            relmse = {(r["method"], r["combiner"]): float(r["relmse"]) for r in rows}
            for member in ("box3", "gauss3", "median5"):
                self.assertLess(relmse[(member, "-")], relmse[("noisy", "-")], member)
            # The oracle's weights minimise each pixel's own error: never worse than a member.
            self.assertLessEqual(
                relmse[("box3+gauss3+median5", "oracle")],
                (1 + 1e-6) * min(relmse[(m, "-")] for m in ("box3", "gauss3", "median5")))
            stamp = os.stat(case).st_mtime_ns
            self.assertEqual(run(*argv).returncode, 0)
            self.assertEqual(os.stat(case).st_mtime_ns, stamp)  # resumed, not recomputed
            other = run(*(argv[:-2] + ["--seed", "5", "--out", tmp]))
            self.assertEqual(other.returncode, 2)
            self.assertIn("settings.txt", other.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
