#!/usr/bin/env python3
"""Runs the evaluation corpus (tools/eval/corpus.json, docs/evaluation.md): per entry one
`chorus sweep` over the corpus's sample counts, methods, combinations and combiners (its
reference rendered and cached in OUT/<entry>/references), then the `--preview` configuration at
4 spp against the same reference (OUT/<entry>.preview); synthetic entries run
tools/eval/synthetic_corpus.cpp instead. Finished cases are kept: a rerun resumes.

    python3 tools/eval/corpus.py [--half tuning|validation] [--shard I/N] [--out DIR]
    python3 tools/eval/summarize.py --dir DIR            # the tables

Python 3 standard library only. Exit code 2 on bad input, else the first failing command's.
"""
import argparse
import os
import shlex
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import corpus_file  # noqa: E402

GENERATOR = os.path.join(corpus_file.REPOSITORY, "tools", "eval", "generate_corpus_scenes.py")


def parse_shard(text):
    try:
        index, count = (int(v) for v in text.split("/"))
    except ValueError:
        raise corpus_file.CorpusError("--shard: expected I/N, got '%s'" % text)
    if not (count >= 1 and 0 <= index < count):
        raise corpus_file.CorpusError("--shard: need 0 <= I < N, got '%s'" % text)
    return index, count


def parse_spp(text):
    try:
        values = [int(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not values or min(values) < 1:
        raise corpus_file.CorpusError("--spp: expected positive integers such as 4,16, got '%s'"
                                      % text)
    return values


def select(corpus, half, only, shard):
    """The entries to run: of `half` (or both), named in `only` (or all), then every N-th."""
    entries = [e for e in corpus["entries"] if half in ("all", e["half"])]
    if only:
        known = {e["name"] for e in corpus["entries"]}
        for name in only:
            if name not in known:
                raise corpus_file.CorpusError("--only: no entry named '%s' in the corpus" % name)
        entries = [e for e in entries if e["name"] in only]
    index, count = shard
    return [e for i, e in enumerate(entries) if i % count == index]


class Paths:
    def __init__(self, args):
        self.out = os.path.abspath(args.out)
        self.shared = args.shared
        self.scenes = os.path.abspath(args.scenes or os.path.join(self.out, "scenes"))

    def resolve(self, reference, flag_hint):
        root, _, rest = reference.partition(":")
        if root == "project":
            return os.path.join(corpus_file.REPOSITORY, rest)
        if root == "generated":
            return os.path.join(self.scenes, rest)
        if root == "shared":
            if not self.shared or not os.path.isdir(self.shared):
                raise corpus_file.CorpusError(
                    "%s: the shared scenes folder '%s' does not exist (set CHORUS_SHARED_DIR or "
                    "--shared)" % (flag_hint, self.shared))
            return os.path.join(self.shared, "scenes", rest)
        raise corpus_file.CorpusError("%s: unknown path root in '%s'" % (flag_hint, reference))


def scene_flags(entry, paths):
    """The flags that make a rendered entry's image: its width, environment and lens (every
    tool that renders an entry passes these, so that its renders match the references)."""
    flags = ["--width", str(entry["width"])]
    if entry.get("env"):
        flags += ["--env", paths.resolve(entry["env"], entry["name"])]
    if entry.get("lens"):
        flags += ["--lens-radius", str(entry["lens"][0]), "--focus-distance", str(entry["lens"][1])]
    return flags


def sweep_commands(entry, corpus, paths, args, spps):
    """[(part, argv)] of a rendered entry: the sweep, then the preview sweep."""
    scene = paths.resolve(entry["scene"], entry["name"])
    common = [scene] + scene_flags(entry, paths) + ["--threads", str(args.threads)]
    out = os.path.join(paths.out, entry["name"])
    reference_spp = args.reference_spp or entry["reference_spp"]
    commands = [("sweep", [args.chorus, "sweep"] + common + [
        "--out", out, "--spp", ",".join(map(str, spps)), "--methods", corpus["methods"],
        "--combos", corpus["combos"], "--combiners", corpus["combiners"],
        "--reference-spp", str(reference_spp)])]
    preview = corpus.get("preview")
    if preview and not args.no_preview:
        preview_spps = [s for s in preview["spp"] if s in spps]
        # The sweep names a scene's reference after the file's stem.
        stem = os.path.splitext(os.path.basename(scene))[0]
        reference = os.path.join(out, "references", stem + ".exr")
        if preview_spps:
            commands.append(("preview", [args.chorus, "sweep"] + common + [
                "--out", out + ".preview", "--spp", ",".join(map(str, preview_spps)),
                "--methods", preview["methods"], "--combos", "all",
                "--combiners", corpus["combiners"], "--reference", reference] + preview["flags"]))
    return commands


def synthetic_command(entry, corpus, paths, args, spps):
    spec = entry["synthetic"]
    return [("synthetic", [
        args.synthetic_tool, "--name", entry["name"], "--scene", spec["scene"],
        "--size", str(spec["size"]), "--seed", str(spec.get("seed", 1)),
        "--noise", str(corpus["synthetic"]["noise"]),
        "--firefly-rate", str(spec.get("firefly_rate", 0.0)),
        "--members", corpus["synthetic"]["members"], "--combiners", corpus["combiners"],
        "--spp", ",".join(map(str, spps)), "--threads", str(args.threads),
        "--out", os.path.join(paths.out, entry["name"])])]


def generate_scenes(paths, entries):
    """Writes the generated scenes into paths.scenes unless all the entries need are there
    (each file moved into place whole, so a concurrent shard never reads half a file)."""
    needed = [paths.resolve(e["scene"], e["name"]) for e in entries
              if e["source"] == "generated"]
    if all(os.path.isfile(f) for f in needed):
        return
    os.makedirs(paths.scenes, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=paths.scenes) as staging:
        subprocess.run([sys.executable, GENERATOR, staging], check=True, stdout=subprocess.DEVNULL)
        for name in os.listdir(staging):
            os.replace(os.path.join(staging, name), os.path.join(paths.scenes, name))
    missing = [f for f in needed if not os.path.isfile(f)]
    if missing:
        raise corpus_file.CorpusError("%s: the generator wrote no such scene" % missing[0])


def clock(seconds):
    s = int(seconds + 0.5)
    return "%d:%02d:%02d" % (s // 3600, s // 60 % 60, s % 60)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--corpus", default=corpus_file.DEFAULT_CORPUS)
    parser.add_argument("--out", default=os.path.join(corpus_file.REPOSITORY, "build", "eval-corpus"),
                        help="output folder: one sweep folder per entry (default: build/eval-corpus)")
    parser.add_argument("--half", choices=("all", "tuning", "validation"), default="all")
    parser.add_argument("--only", help="comma-separated entry names")
    parser.add_argument("--shard", default="0/1",
                        help="I/N: run only every N-th selected entry, starting at the I-th")
    parser.add_argument("--chorus", default=os.path.join(corpus_file.REPOSITORY, "build", "chorus"))
    parser.add_argument("--synthetic-tool", default=os.path.join(
        corpus_file.REPOSITORY, "build", "eval", "synthetic_corpus"))
    parser.add_argument("--shared", default=os.environ.get("CHORUS_SHARED_DIR") or os.path.join(
        os.path.dirname(corpus_file.REPOSITORY), "shared"),
                        help="the shared scenes folder (default: $CHORUS_SHARED_DIR or ../shared)")
    parser.add_argument("--scenes", help="folder of the generated scenes (default: OUT/scenes)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--spp", help="override the corpus's sample counts (trials only)")
    parser.add_argument("--reference-spp", type=int,
                        help="override every entry's reference spp (trials only)")
    parser.add_argument("--no-preview", action="store_true", help="skip the --preview sweeps")
    parser.add_argument("--dry-run", action="store_true", help="print the commands only")
    args = parser.parse_args(argv)
    try:
        corpus = corpus_file.load(args.corpus)
        shard = parse_shard(args.shard)
        spps = parse_spp(args.spp) if args.spp else corpus["spp"]
        if args.threads < 0:
            raise corpus_file.CorpusError("--threads: must be at least 0")
        if args.reference_spp is not None and args.reference_spp < 1:
            raise corpus_file.CorpusError("--reference-spp: must be positive")
        only = [n for n in args.only.split(",") if n] if args.only else None
        entries = select(corpus, args.half, only, shard)
        paths = Paths(args)
        plan = []
        for entry in entries:
            make = synthetic_command if entry["source"] == "synthetic" else sweep_commands
            plan.append((entry, make(entry, corpus, paths, args, spps)))
        if not args.dry_run:
            for tool in {argv_[0] for _, commands in plan for _, argv_ in commands}:
                if not os.access(tool, os.X_OK):
                    raise corpus_file.CorpusError("%s: not an executable (build it first: "
                                                  "bash tools/setup.sh build)" % tool)
            generate_scenes(paths, entries)
    except corpus_file.CorpusError as e:
        print("corpus: %s" % e, file=sys.stderr)
        return 2

    if args.dry_run:
        for entry, commands in plan:
            for part, command in commands:
                print("# %s (%s) %s\n%s" % (entry["name"], entry["half"], part,
                                            shlex.join(command)))
        return 0

    os.makedirs(paths.out, exist_ok=True)
    start = time.monotonic()
    print("corpus: %d entr%s (%s half, shard %s) into %s" % (
        len(plan), "y" if len(plan) == 1 else "ies", args.half, args.shard, paths.out),
        file=sys.stderr, flush=True)
    for k, (entry, commands) in enumerate(plan, 1):
        for part, command in commands:
            print("corpus: [%d/%d] %s (%s, %s) %s, elapsed %s" % (
                k, len(plan), entry["name"], entry["half"], entry["source"], part,
                clock(time.monotonic() - start)), file=sys.stderr, flush=True)
            part_start = time.monotonic()
            result = subprocess.run(command)
            if result.returncode != 0:
                print("corpus: %s %s failed (exit code %d): %s" % (
                    entry["name"], part, result.returncode, shlex.join(command)),
                    file=sys.stderr)
                return result.returncode
            with open(os.path.join(paths.out, "timings.tsv"), "a", encoding="utf-8") as f:
                f.write("%s\t%s\t%.1f\t%s\n" % (entry["name"], part,
                                                time.monotonic() - part_start,
                                                time.strftime("%Y-%m-%d %H:%M:%S")))
    print("corpus: done, %s" % clock(time.monotonic() - start), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
