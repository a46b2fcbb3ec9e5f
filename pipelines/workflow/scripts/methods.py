#!/usr/bin/env python3
"""The method lists of the suite's method tools, asked from the tools themselves (issue 21: no pipeline repeats a
fact a registry knows). Used by pipelines/lib.sh (`methods_of`, `method_args`) and by the Snakefile (`stateful`,
the experiments' `methods:` lists).

Where the list comes from, in order:
  1. `TOOL --list-methods-json`: a JSON array, one object per method or named variant:
     {"name", "method", "args": [...], "summary", "stateful": bool, "implementations": [...]}.
  2. `TOOL --list-methods`, tab-separated: upsample-st prints NAME, "--method M ARGS...", SUMMARY per method and
     named variant and *SUFFIX, ARGS, SUMMARY per name suffix (-demod); morph-120hz prints NAME, SUMMARY.
  3. TRANSITIONAL (remove once every method tool has --list-methods-json): filter-phlm without either option
     gets the methods of libtemporal/src/phlm/registry.cpp below, and a tool without the JSON form gets the
     statefulness of TRANSITIONAL_STATELESS (upsample's MethodInfo::has_state, FrameFilter::has_state).
Name suffixes (*-demod) are read from the tab-separated listing in every case: the JSON form lists methods and
variants only.

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

# TRANSITIONAL: filter-phlm before it had --list-methods (libtemporal/src/phlm/registry.cpp, in its order).
TRANSITIONAL_METHODS = {"filter-phlm": ["phlm", "taa", "ema", "fxaa"]}
# TRANSITIONAL: the methods without a history, for tools without --list-methods-json (they refuse --state-in /
# --state-out). morph-120hz has no --state-in / --state-out at all.
TRANSITIONAL_STATELESS = {"upsample-st": {"spatial"}, "filter-phlm": {"fxaa"}}
TRANSITIONAL_NO_STATE_TOOLS = {"morph-120hz"}


class Registry:
    def __init__(self, tool, entries, suffixes, source):
        self.tool = tool          # the tool's file name (upsample-st, ...)
        self.entries = entries    # [{name, method, args, summary, stateful}] in the tool's order
        self.suffixes = suffixes  # [(suffix, args, summary)]
        self.source = source      # "json", "list" or "transitional": where the entries came from

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
        if e["stateful"] is not None:
            return bool(e["stateful"])
        # TRANSITIONAL: no --list-methods-json yet.
        if self.tool in TRANSITIONAL_NO_STATE_TOOLS:
            return False
        return e["method"] not in TRANSITIONAL_STATELESS.get(self.tool, set())


def _ask(path, option):
    """stdout of `TOOL OPTION`, or None when the tool does not know the option (it exits non-zero)."""
    try:
        r = subprocess.run([path, option], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    except OSError as e:
        raise SystemExit(f"methods.py: cannot run {path}: {e}")
    return r.stdout if r.returncode == 0 else None


def _from_json(text):
    data = json.loads(text)
    items = data if isinstance(data, list) else data.get("methods", [])
    entries = []
    for m in items:
        entries.append({"name": m["name"], "method": m.get("method", m["name"]), "args": list(m.get("args", [])),
                        "summary": m.get("summary", ""), "stateful": m.get("stateful")})
    return entries


def _from_list(text):
    entries, suffixes = [], []
    for line in text.splitlines():
        if not line.strip():
            continue
        fields = line.split("\t")
        if fields[0].startswith("*"):  # a name suffix: *SUFFIX, ARGS, SUMMARY
            suffixes.append((fields[0][1:], shlex.split(fields[1]) if len(fields) > 1 else [],
                             fields[2] if len(fields) > 2 else ""))
        elif len(fields) >= 3 and fields[1].startswith("--method "):  # NAME, --method M ARGS, SUMMARY
            words = shlex.split(fields[1])
            entries.append({"name": fields[0], "method": words[1], "args": words[2:], "summary": fields[2],
                            "stateful": None})
        else:  # NAME, SUMMARY
            entries.append({"name": fields[0], "method": fields[0], "args": [],
                            "summary": fields[1] if len(fields) > 1 else "", "stateful": None})
    return entries, suffixes


def load(path):
    """The registry of the tool at PATH."""
    tool = os.path.basename(path)
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        raise SystemExit(f"methods.py: {path} is not built: build the tools first (docs/pipelines.md, \"Running it\")")
    listing = _ask(path, "--list-methods")
    list_entries, suffixes = _from_list(listing) if listing is not None else ([], [])
    text = _ask(path, "--list-methods-json")
    if text is not None:
        try:
            return Registry(tool, _from_json(text), suffixes, "json")
        except (ValueError, KeyError, AttributeError, TypeError) as e:
            raise SystemExit(f"methods.py: {tool} --list-methods-json: unreadable output ({e})")
    if listing is not None:
        return Registry(tool, list_entries, suffixes, "list")
    if tool in TRANSITIONAL_METHODS:
        entries = [{"name": m, "method": m, "args": [], "summary": "", "stateful": None}
                   for m in TRANSITIONAL_METHODS[tool]]
        return Registry(tool, entries, [], "transitional")
    raise SystemExit(f"methods.py: {tool} has neither --list-methods-json nor --list-methods")


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
