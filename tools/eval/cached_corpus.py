#!/usr/bin/env python3
"""Combine-only runs of the evaluation corpus (docs/evaluation.md): cache every case's inputs
once, then re-run only the ensemble's combination step for many option settings.

    python3 tools/eval/cached_corpus.py build [--half H] [--only A,B] [--references-from DIR]
    python3 tools/eval/cached_corpus.py combine VARIANT [--half H] [--only A,B] [-- FLAGS...]

`build` renders each rendered entry's cases with `chorus render --denoise none` (K = 4, the
seed and settings of `chorus sweep`, so the noisy inputs equal a corpus run's), writes each
synthetic entry's render and truth, and runs build/eval/ensemble_cache: every member of the
corpus (and the --preview members at the preview spp) on half A, half B, the full buffer and the
four leave-one-quarter-out inputs. References are copied from a corpus run (--references-from,
OUT/<entry>/references/) or rendered by a one-case `chorus sweep`. Output: CACHE/<entry>/.

`combine` runs build/eval/combine_cached over the cached entries with the ensemble FLAGS (those
of `chorus denoise`; the preview rows get the --preview defaults unless the flags set them) and
writes CACHE/variants/VARIANT/, a folder summarize.py reads like a corpus run; then prints
summarize.py's one-line figures per half. Python 3 standard library only.
"""
import argparse
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import corpus  # noqa: E402
import corpus_file  # noqa: E402

BUILD = os.path.join(corpus_file.REPOSITORY, "build")


def entry_args(entry, paths):
    """The scene and render flags of a rendered entry, as corpus.py gives them to the sweep."""
    return paths.resolve(entry["scene"], entry["name"]), corpus.scene_flags(entry, paths)


def run(command, quiet=False):
    result = subprocess.run(command, stdout=subprocess.DEVNULL if quiet else None)
    if result.returncode != 0:
        raise SystemExit("cached_corpus: failed (exit code %d): %s" % (
            result.returncode, " ".join(command)))


def reference(entry, paths, args, folder):
    target = os.path.join(folder, "reference.exr")
    if os.path.exists(target):
        return
    scene, flags = entry_args(entry, paths)
    stem = os.path.splitext(os.path.basename(scene))[0]
    if args.references_from:
        source = os.path.join(args.references_from, entry["name"], "references", stem + ".exr")
        if os.path.exists(source):
            shutil.copyfile(source, target + ".part")
            os.replace(target + ".part", target)
            return
    # As the sweep renders its references (tools/sweep/reference_render.h): K = 1, seed 1000;
    # render.exr's default layer is the colour mean.
    rendered = os.path.join(folder, "reference-render")
    run([args.chorus, "render", scene] + flags + [
        "--threads", str(args.threads), "--out", rendered, "--spp", str(entry["reference_spp"]),
        "--splits", "1", "--seed", "1000", "--denoise", "none", "--quiet"], quiet=True)
    os.replace(os.path.join(rendered, "render.exr"), target)
    shutil.rmtree(rendered)


def build(args, data, entries, paths):
    preview = data.get("preview", {})
    for k, entry in enumerate(entries, 1):
        folder = os.path.join(args.cache, entry["name"])
        os.makedirs(folder, exist_ok=True)
        start = time.monotonic()
        synthetic = entry["source"] == "synthetic"
        if not synthetic:
            reference(entry, paths, args, folder)
        for spp in args.spps:
            case = os.path.join(folder, "spp%d" % spp)
            methods = data["synthetic"]["members"] if synthetic else data["methods"]
            command = [args.ensemble_cache, "--case", case, "--threads", str(args.threads)]
            if synthetic:
                spec = entry["synthetic"]
                command += ["--synthetic", ",".join(str(v) for v in (
                    spec["scene"], spec["size"], spec.get("seed", 1), data["synthetic"]["noise"],
                    spec.get("firefly_rate", 0.0), spp))]
            else:
                if spp in preview.get("spp", []):
                    known = methods.split(",")
                    methods += "".join("," + m for m in preview["methods"].split(",")
                                       if m not in known)
                if not os.path.exists(os.path.join(case, "render.exr")):
                    scene, flags = entry_args(entry, paths)
                    run([args.chorus, "render", scene] + flags + [
                        "--spp", str(spp), "--denoise", "none", "--threads", str(args.threads),
                        "--out", case, "--quiet"], quiet=True)
            run(command + ["--methods", methods])
        if synthetic:  # one truth per spp (the firefly mean shift does not depend on spp)
            first = os.path.join(folder, "spp%d" % args.spps[0], "reference.exr")
            if not os.path.exists(os.path.join(folder, "reference.exr")):
                shutil.copyfile(first, os.path.join(folder, "reference.exr"))
        print("cached_corpus: [%d/%d] %s cached in %.0f s" % (
            k, len(entries), entry["name"], time.monotonic() - start), file=sys.stderr, flush=True)


def combine(args, data, entries):
    out = os.path.join(args.cache, "variants", args.variant)
    if os.path.exists(out):
        shutil.rmtree(out)
    preview = data.get("preview", {})
    start = time.monotonic()
    for entry in entries:
        folder = os.path.join(args.cache, entry["name"])
        if not os.path.isdir(folder):
            continue
        synthetic = entry["source"] == "synthetic"
        command = [args.combine_cached, "--cache", folder, "--name", entry["name"], "--out", out,
                   "--threads", str(args.threads), "--combiners", args.combiners,
                   "--spp", ",".join(map(str, args.spps))]
        if synthetic:
            command += ["--methods", data["synthetic"]["members"], "--combos", "all"]
        else:
            command += ["--methods", data["methods"], "--combos", data["combos"]]
            if preview and not args.no_preview:
                command += ["--preview-methods", preview["methods"],
                            "--preview-spp", ",".join(map(str, preview["spp"]))]
        run(command + args.flags)
    seconds = time.monotonic() - start
    with open(os.path.join(out, "flags.txt"), "w", encoding="utf-8") as f:
        f.write(" ".join(args.flags) + "\n")
    print("cached_corpus: variant %s (%s) combined in %.0f s" % (
        args.variant, " ".join(args.flags) or "defaults", seconds), file=sys.stderr)
    halves = [args.half] if args.half != "all" else list(corpus_file.HALVES)
    for half in halves:
        run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                          "summarize.py"), "--dir", out, "--half", half, "--brief",
             "--label", args.variant])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mode", choices=("build", "combine"))
    parser.add_argument("variant", nargs="?", help="combine: the variant's name")
    parser.add_argument("--corpus", default=corpus_file.DEFAULT_CORPUS)
    parser.add_argument("--cache", default=os.path.join(BUILD, "eval-cache"))
    parser.add_argument("--half", choices=("all", "tuning", "validation"), default="tuning")
    parser.add_argument("--only", help="comma-separated entry names")
    parser.add_argument("--spp", help="override the corpus's sample counts")
    parser.add_argument("--references-from", help="a corpus.py output folder")
    parser.add_argument("--shared", default=os.environ.get("CHORUS_SHARED_DIR") or os.path.join(
        os.path.dirname(corpus_file.REPOSITORY), "shared"))
    parser.add_argument("--scenes", help="folder of the generated scenes (default: CACHE/scenes)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--combiners", default="ensemble,onehot-pre,onehot-post,average,oracle")
    parser.add_argument("--no-preview", action="store_true")
    parser.add_argument("--chorus", default=os.path.join(BUILD, "chorus"))
    parser.add_argument("--ensemble-cache", default=os.path.join(BUILD, "eval", "ensemble_cache"))
    parser.add_argument("--combine-cached", default=os.path.join(BUILD, "eval", "combine_cached"))
    argv = list(sys.argv[1:] if argv is None else argv)
    split = argv.index("--") if "--" in argv else len(argv)
    args = parser.parse_args(argv[:split])
    args.flags = argv[split + 1:]
    try:
        data = corpus_file.load(args.corpus)
        args.spps = corpus.parse_spp(args.spp) if args.spp else data["spp"]
        only = [n for n in args.only.split(",") if n] if args.only else None
        entries = corpus.select(data, args.half, only, (0, 1))
        if args.mode == "combine" and not args.variant:
            raise corpus_file.CorpusError("combine: name the variant")
        args.out = args.cache
        args.scenes = args.scenes or os.path.join(args.cache, "scenes")
        paths = corpus.Paths(args)
        if args.mode == "build":
            corpus.generate_scenes(paths, entries)
    except corpus_file.CorpusError as e:
        print("cached_corpus: %s" % e, file=sys.stderr)
        return 2
    if args.mode == "build":
        build(args, data, entries, paths)
    else:
        combine(args, data, entries)
    return 0


if __name__ == "__main__":
    sys.exit(main())
