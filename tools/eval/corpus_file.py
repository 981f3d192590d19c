"""Reading and checking tools/eval/corpus.json: the evaluation corpus and its split into a
tuning half and a validation half (docs/evaluation.md). Shared by corpus.py and summarize.py."""
import json
import os

HALVES = ("tuning", "validation")
SOURCES = ("project", "shared", "generated", "synthetic")
REPOSITORY = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DEFAULT_CORPUS = os.path.join(REPOSITORY, "tools", "eval", "corpus.json")


class CorpusError(Exception):
    """Bad input: the message is one line naming the file or flag and the problem."""


def _require(condition, path, message):
    if not condition:
        raise CorpusError("%s: %s" % (path, message))


def load(path=DEFAULT_CORPUS):
    """The corpus as a dict, checked: unique names, known halves and sources, and every scene
    file (with or without an environment) in one half only."""
    try:
        with open(path, encoding="utf-8") as f:
            corpus = json.load(f)
    except OSError as e:
        raise CorpusError("%s: cannot read (%s)" % (path, e.strerror))
    except json.JSONDecodeError as e:
        raise CorpusError("%s: not valid JSON (line %d: %s)" % (path, e.lineno, e.msg))
    _require(isinstance(corpus, dict) and isinstance(corpus.get("entries"), list), path,
             "expected an object with an 'entries' list")
    for key in ("spp", "methods", "combos", "combiners"):
        _require(key in corpus, path, "missing '%s'" % key)
    _require(all(isinstance(s, int) and s > 0 for s in corpus["spp"]), path,
             "'spp' must list positive integers")
    names, half_of_scene = set(), {}
    for i, entry in enumerate(corpus["entries"]):
        label = "entry %d (%s)" % (i, entry.get("name", "no name"))
        _require(isinstance(entry.get("name"), str) and entry["name"], path, label + ": no name")
        _require(entry["name"] not in names, path, label + ": name used twice")
        names.add(entry["name"])
        _require(entry.get("half") in HALVES, path, label + ": half must be tuning or validation")
        _require(entry.get("source") in SOURCES, path,
                 label + ": source must be one of " + ", ".join(SOURCES))
        if entry["source"] == "synthetic":
            spec = entry.get("synthetic")
            _require(isinstance(spec, dict) and "scene" in spec and "size" in spec, path,
                     label + ": a synthetic entry needs synthetic.scene and synthetic.size")
            scene_key = "synthetic:" + spec["scene"]
        else:
            _require(isinstance(entry.get("scene"), str), path, label + ": no scene")
            _require(entry["scene"].split(":", 1)[0] == entry["source"], path,
                     label + ": scene must start with '%s:'" % entry["source"])
            _require(isinstance(entry.get("width"), int) and 16 <= entry["width"] <= 4096, path,
                     label + ": width must be an integer in 16..4096")
            _require(isinstance(entry.get("reference_spp"), int) and entry["reference_spp"] > 0,
                     path, label + ": reference_spp must be a positive integer")
            lens = entry.get("lens")
            _require(lens is None or (isinstance(lens, list) and len(lens) == 2 and all(
                isinstance(v, (int, float)) and v >= 0 for v in lens) and lens[0] > 0), path,
                label + ": lens must be [radius > 0, focus distance >= 0 (0: autofocus)]")
            scene_key = entry["scene"]
        other = half_of_scene.setdefault(scene_key, entry["half"])
        _require(other == entry["half"], path,
                 label + ": its scene %s is also in the %s half (split by scene)" %
                 (scene_key, other))
    return corpus


def half_of(corpus):
    """Entry name -> half."""
    return {e["name"]: e["half"] for e in corpus["entries"]}
