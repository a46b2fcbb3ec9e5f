#!/usr/bin/env python3
"""The method lists of the suite's method tools, asked from the tools themselves (issue 21: no pipeline repeats a
fact a registry knows). Used by pipelines/lib.sh (`methods_of`, `method_args`) and by the Snakefile (`stateful`,
the experiments' `methods:` lists).

The list is `TOOL --list-methods-json` (upsample-st, filter-phlm and morph-120hz print it from their registries): a
JSON array with one object per method or named variant,
    {"name", "method", "args": [...], "summary", "stateful": bool, "implementations": [...]},
and one object per name suffix (upsample-st's `-demod`: any method with extra arguments),
    {"suffix", "args": [...], "summary"}.

  methods.py names TOOL           the methods (not the named variants), one per line
  methods.py args TOOL NAME...    per NAME (a method, a named variant, either with suffixes) "NAME<TAB>ARGUMENTS"
  methods.py stateful TOOL NAME   prints true / false: the method keeps a history between frames
  methods.py table TOOL           every entry: NAME, ARGUMENTS, STATEFUL, SUMMARY (tab-separated), then suffixes
"""
import json
import os
import shlex
import subprocess
import sys

class Registry:
    def __init__(self, tool, entries, suffixes):
        self.tool = tool          # the tool's file name (upsample-st, ...)
        self.entries = entries    # [{name, method, args, summary, stateful}] in the tool's order
        self.suffixes = suffixes  # [(suffix, args, summary)]

    def names(self):
        """The methods themselves (an entry that is its own method with no extra arguments)."""
        return [e["name"] for e in self.entries if e["name"] == e["method"] and not e["args"]]

    def entry(self, name):
        for e in self.entries:
            if e["name"] == name:
                return e
        return None

    def resolve(self, name):
        """(entry, extra arguments) of NAME: an entry's name, possibly followed by name suffixes."""
        extra = []
        rest = name
        while True:
            e = self.entry(rest)
            if e is not None:
                return e, extra
            for suffix, args, _ in self.suffixes:
                if rest.endswith(suffix) and len(rest) > len(suffix):
                    rest = rest[: -len(suffix)]
                    extra = args + extra
                    break
            else:
                raise KeyError(f"{self.tool}: unknown method '{name}' (`{self.tool} --list-methods` lists the names)")

    def args(self, name):
        """The tool arguments that run NAME: --method M, the variant's arguments, then its suffixes' arguments."""
        e, extra = self.resolve(name)
        return ["--method", e["method"]] + list(e["args"]) + extra

    def stateful(self, name):
        e, _ = self.resolve(name)
        return bool(e["stateful"])


def _ask(path, option):
    """stdout of `TOOL OPTION`, or None when the tool does not know the option (it exits non-zero)."""
    try:
        r = subprocess.run([path, option], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    except OSError as e:
        raise SystemExit(f"methods.py: cannot run {path}: {e}")
    return r.stdout if r.returncode == 0 else None


def _from_json(text):
    """(entries, suffixes) of the JSON listing."""
    entries, suffixes = [], []
    for m in json.loads(text):
        if "suffix" in m:
            suffixes.append((m["suffix"], list(m.get("args", [])), m.get("summary", "")))
        else:
            entries.append({"name": m["name"], "method": m.get("method", m["name"]), "args": list(m.get("args", [])),
                            "summary": m.get("summary", ""), "stateful": bool(m["stateful"])})
    return entries, suffixes


def load(path):
    """The registry of the tool at PATH."""
    tool = os.path.basename(path)
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        raise SystemExit(f"methods.py: {path} is not built: build the tools first (docs/pipelines.md, \"Running it\")")
    text = _ask(path, "--list-methods-json")
    if text is None:
        raise SystemExit(f"methods.py: {tool} has no --list-methods-json: rebuild it from this checkout")
    try:
        entries, suffixes = _from_json(text)
    except (ValueError, KeyError, AttributeError, TypeError) as e:
        raise SystemExit(f"methods.py: {tool} --list-methods-json: unreadable output ({e})")
    return Registry(tool, entries, suffixes)


def main(argv):
    if len(argv) < 3 or argv[1] not in ("names", "args", "stateful", "table"):
        sys.stderr.write(__doc__)
        return 1
    reg = load(argv[2])
    try:
        if argv[1] == "names":
            print("\n".join(reg.names()))
        elif argv[1] == "args":
            for name in argv[3:]:
                print(name + "\t" + " ".join(shlex.quote(a) for a in reg.args(name)))
        elif argv[1] == "stateful":
            print("true" if reg.stateful(argv[3]) else "false")
        else:
            for e in reg.entries:
                print("\t".join([e["name"], " ".join(reg.args(e["name"])),
                                 "true" if reg.stateful(e["name"]) else "false", e["summary"]]))
            for suffix, args, summary in reg.suffixes:
                print("\t".join(["*" + suffix, " ".join(args), "", summary]))
    except KeyError as e:
        sys.stderr.write(e.args[0] + "\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
