#!/usr/bin/env python3
"""Execution-port floor of a method: the cycles per pixel its instructions need on one core if every execution
unit were busy every cycle, from what ran (callgrind, per instruction) and what each instruction occupies
(llvm-mca's scheduling model of the CPU, per instruction); with --perf, next to the measured time per function.

Why: issue 27 asks for speed ratios (herzog at most 2.5x spatial, drobot at most 4x its streaming bound) on the
build machine, and where the arithmetic sets the floor, for the count instead of the claim. Instruction counts
alone do not say that: an instruction that needs the floating-point multiply pipes (two on Zen 3: FP0, FP1) costs
more than one that any of four vector pipes runs. This tool turns callgrind's exact count of every executed
instruction into the busy cycles of each group of units, per function, and reports the largest (the function's
floor: no schedule runs it faster) next to the instructions. Deterministic: the same binary gives the same numbers
on any host, so a code change shows its effect without timing noise.

What the floor leaves out (so measured time is above it): dependency chains (latency), memory and cache misses,
branch misses, the front end. llvm-mca is a model; its Zen 3 tables are AMD's and LLVM's, not measurements here.
--perf measures how far above it each function runs: one more run of the same benchmark, pinned to one CPU, under
`perf record -e cpu-clock` (a software clock: it works in VMs without hardware counters). A function's time per
pixel is its share of the samples in the functions the floor counts, times the benchmark's median time per pixel;
its efficiency is floor / (time x clock), a lower bound when --ghz is the highest clock the core runs at.

Usage (release builds of the benchmarks, the `ci` preset):
  tests/benchmarks/port_floor.py build/ci/tests/benchmarks/upsample/upsample_benchmark spatial herzog
  tests/benchmarks/port_floor.py BENCH spatial herzog drobot taau --scale 1 --cpu znver3 --isa v3
  tests/benchmarks/port_floor.py build/ci/tests/benchmarks/phlm/phlm_bench phlm taa --perf --ghz 2.9
Needs valgrind, binutils' objdump and llvm-mca (Debian: apt-get install valgrind binutils llvm), and perf for
--perf (Debian: linux-perf); c++filt is not needed (callgrind demangles). Each method is two valgrind runs of its
one-thread benchmark with a fixed iteration count (UPSAMPLE_BENCH_ITERATIONS or PHLM_BENCH_ITERATIONS = 1 and 3;
the difference is two frames in the steady state, without the set-up both runs share). upsample_benchmark's
BM_PerPixel: about two minutes per run at --scale 1 (1280x1024), seconds at --scale 4 (320x256). phlm_bench's
one-thread, fractional-motion benchmarks (1920x1080): phlm, phlm-catmull-rom, taa, taa-2014, ema; a few minutes
per run.
"""
import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

# Groups of identical units in llvm-mca's resource names (AMD Zen 3: Zn3FPP0 ...; the same idea for other models):
# the busy cycles of a group are its units' summed pressure divided by the number of units.
GROUPS = [
    ("FP mul/FMA/cmp (FP0, FP1)", re.compile(r"FPP?[01]$")),
    ("FP add (FP2, FP3)", re.compile(r"FPP?[23]$")),
    ("FP store/convert (FP45)", re.compile(r"FPP?45")),
    ("loads", re.compile(r"Load")),
    ("stores", re.compile(r"Store$")),
    ("integer ALU", re.compile(r"ALU\d")),
    ("address (AGU)", re.compile(r"AGU\d")),
]
DISPATCH_WIDTH = {"znver3": 6, "znver2": 5, "znver4": 6, "skylake": 4, "icelake-server": 5, "sapphirerapids": 6}
# Instructions llvm-mca cannot schedule on their own (control flow, prefixes): counted as instructions, no units.
UNSCHEDULED = ("j", "call", "ret", "nop", "endbr", "ud2", "int3", "lock", "rep", "bnd", "notrack", "cs ", "ds ",
               "data16", "xchg", "cmpxchg", "pause", "leave", "syscall")

# upsample_benchmark's sizes (upsample_benchmark.cpp): full size, and a quarter per axis.
SIZE = {1: (1280, 1024), 4: (320, 256)}
# phlm_bench's one-thread benchmarks with fractional motion (phlm_bench.cpp, 1920x1080): method -> (benchmark, the
# function whose calls are the frames).
PHLM = {
    "phlm": ("BM_Phlm/motion:1/threads:1/", "PhlmFilter::process"),
    "phlm-catmull-rom": ("BM_PhlmCatmullRom/motion:1/threads:1/", "PhlmFilter::process"),
    "taa": ("BM_Taa/motion:1/threads:1/", "TaaFilter::process"),
    "taa-2014": ("BM_Taa2014/motion:1/threads:1/", "TaaFilter::process"),
    "ema": ("BM_Ema/motion:1/threads:1/", "EmaFilter::process"),
}
PHLM_SIZE = (1920, 1080)

# One method's benchmark: the --benchmark_filter that runs one thread of it, the variable that fixes the iteration
# count, the function whose calls are its frames (and whose callees are the method) and the frame size.
Target = collections.namedtuple("Target", "name filter env root width height")


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw).stdout


def method_index(bench, name):
    # BM_PerPixel/<index>/<scale>: the label of each printed line names the method; list and match by a dry run.
    out = run([bench, "--benchmark_list_tests"])
    ids = sorted({int(m.group(1)) for m in re.finditer(r"^BM_PerPixel/(\d+)/", out, re.M)})
    for i in ids:
        env = dict(os.environ, UPSAMPLE_BENCH_ITERATIONS="1")
        o = run([bench, f"--benchmark_filter=BM_PerPixel/{i}/4/"], env=env)
        if re.search(rf"per_pixel=\S+\s+{re.escape(name)} ", o):
            return i
    sys.exit(f"port_floor: {bench}: no BM_PerPixel entry for method '{name}' (BM_PerPixel runs spatial, temporal, "
             "herzog, drobot, taau)")


def target(bench, name, scale):
    """The Target of method `name` in benchmark program `bench` (upsample_benchmark or phlm_bench)."""
    if os.path.basename(bench).startswith("phlm_bench"):
        if name not in PHLM:
            sys.exit(f"port_floor: phlm_bench has no one-thread benchmark for '{name}' (it has {', '.join(PHLM)})")
        bm, root = PHLM[name]
        return Target(name, bm, "PHLM_BENCH_ITERATIONS", root, *PHLM_SIZE)
    idx = method_index(bench, name)
    return Target(name, f"BM_PerPixel/{idx}/{scale}/", "UPSAMPLE_BENCH_ITERATIONS", "Upsampler::process", *SIZE[scale])


def normalise(fn):
    # Function names without return types, argument lists and clone suffixes, so that one function's parts group
    # together and callgrind's names (return types on template instances) meet perf's.
    prev = None
    while prev != fn:
        prev = fn
        fn = re.sub(r"\([^()]*\)", "", fn)
    fn = re.sub(r"\s*\[clone[^\]]*\]", "", fn).replace(" const", "").strip()
    # A leading return type: words before the qualified name ("void ", "int ", "unsigned long ").
    return re.sub(r"^(?:[A-Za-z_]\w*[*&]* )+(?=[A-Za-z_~])", "", fn)


def read_callgrind(path, binary, root="Upsampler::process"):
    """Per function of `binary`: {address: executed count}; the call graph; the calls of `root` (the frames)."""
    counts = collections.defaultdict(collections.Counter)
    callees = collections.defaultdict(set)
    ob = fn = cfn = None
    after_calls = False
    process_calls = 0
    real = os.path.realpath(binary)
    with open(path) as f:
        for line in f:
            if line.startswith("ob="):
                ob = os.path.realpath(line[3:].strip())
            elif line.startswith("fn="):
                fn = normalise(line[3:].strip())
            elif line.startswith("cfn="):
                cfn = normalise(line[4:].strip())
            elif line.startswith("calls="):
                after_calls = True
                callees[fn].add(cfn)
                if cfn.endswith(root) and not fn.endswith(root):
                    process_calls += int(line[6:].split()[0])
            elif line.startswith("0x"):
                if after_calls:  # the line after calls= is the call's inclusive cost, not an instruction
                    after_calls = False
                    continue
                if ob != real:
                    continue
                addr, _, count = line.split()
                counts[fn][int(addr, 16)] += int(count)
    return counts, callees, process_calls


def reachable(callees, root_suffix):
    roots = [f for f in callees if f.endswith(root_suffix)]
    seen, todo = set(roots), list(roots)
    while todo:
        for c in callees.get(todo.pop(), ()):
            if c not in seen:
                seen.add(c)
                todo.append(c)
    return seen


def disassemble(binary):
    text = {}
    for line in run(["objdump", "-d", "--no-show-raw-insn", binary]).splitlines():
        m = re.match(r"\s+([0-9a-f]+):\t(.*)", line)
        if m:
            text[int(m.group(1), 16)] = m.group(2).split("#")[0].split("<")[0].strip()
    return text


def unit_pressure(instructions, cpu):
    """{instruction text: {group: busy cycles}}: each distinct instruction in a code region of its own, repeated
    (llvm-mca -iterations), so that its cycles spread over every unit that can run it. (One region over all of
    them would give each instruction the units left free by its neighbours in the list: a number that depends on
    which other instructions the method happens to contain.)"""
    texts = sorted(instructions)
    sched = [t for t in texts if not t.startswith(UNSCHEDULED)]
    # An instruction llvm-mca does not parse stops the whole run: drop the lines it names and run again.
    while True:
        with tempfile.NamedTemporaryFile("w", suffix=".s", delete=False) as f:
            for t in sched:  # instruction i on line 3 i + 2
                f.write(f"# LLVM-MCA-BEGIN\n{t}\n# LLVM-MCA-END\n")
            src = f.name
        try:
            r = subprocess.run(["llvm-mca", f"-mcpu={cpu}", "-iterations=100", "-resource-pressure", "-timeline=false",
                                "-instruction-info=false", src], capture_output=True, text=True)
        finally:
            os.unlink(src)
        bad = {(int(m.group(1)) - 2) // 3 for m in re.finditer(r"\.s:(\d+):\d+: error", r.stderr)}
        if r.returncode == 0 and not bad:
            out = r.stdout
            break
        if not bad:
            sys.exit(f"port_floor: llvm-mca failed: {r.stderr.strip()[:400]}")
        sched = [t for i, t in enumerate(sched) if i not in bad]
    names = {m.group(1): m.group(2) for m in re.finditer(r"^\[([\d.]+)\]\s+-\s+(\S+)", out, re.M)}
    tables = out.split("Resource pressure by instruction:")[1:]
    if len(tables) != len(sched):
        sys.exit(f"port_floor: llvm-mca reported {len(tables)} regions for {len(sched)}: its output format changed?")
    cols = re.findall(r"\[([\d.]+)\]", tables[0].splitlines()[1])
    col_group = [next((g for g, rx in GROUPS if rx.search(names.get(c, c))), None) for c in cols]
    units_per_group = collections.Counter(g for g in col_group if g)
    pressure = {t: {} for t in texts}
    for t, table in zip(sched, tables):
        row = [l for l in table.splitlines()[2:] if l.strip()][0]
        p = collections.Counter()
        for g, v in zip(col_group, row.split()[: len(cols)]):
            if g and v != "-":
                p[g] += float(v) / units_per_group[g]
        pressure[t] = p
    return pressure


def read_perf_report(text):
    """{function: percent of the samples} from `perf report --stdio --no-children --sort sym` (user-space lines
    `  12.34%  [.] name`; the kernel's `[k]` lines are left out), names normalised as callgrind's."""
    shares = collections.Counter()
    for line in text.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+\[\.\]\s+(.+?)\s*$", line)
        if m:
            shares[normalise(m.group(2))] += float(m.group(1))
    return shares


def function_times(shares, inside, ns_per_pixel):
    """Each function's time per pixel: its share of the samples in the functions the floor counts (`inside`), times
    the measured time per pixel. Also returns the fraction of all user samples those functions hold."""
    within = {f: v for f, v in shares.items() if f in inside}
    total = sum(within.values())
    if total <= 0:
        return {}, 0.0
    return {f: v / total * ns_per_pixel for f, v in within.items()}, total / max(sum(shares.values()), 1e-9)


def median_ns_per_pixel(benchmark_json, pixels):
    """The median repetition's real time per iteration (Google Benchmark's JSON output) per pixel, in ns."""
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
    for b in json.loads(benchmark_json)["benchmarks"]:
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median":
            return b["real_time"] * scale[b["time_unit"]] / pixels
    sys.exit("port_floor: the benchmark's JSON has no median (was it run with --benchmark_repetitions=3?)")


def measure(bench, t, isa, folder):
    """One run of the method's one-thread benchmark (3 repetitions) on one CPU under perf's software clock: the
    report of its samples per function and the median time per pixel."""
    cpu = max(os.sched_getaffinity(0))
    data = os.path.join(folder, f"perf.{t.name}.data")
    out = os.path.join(folder, f"bench.{t.name}.json")
    env = dict(os.environ, TEMPORAL_ISA=isa)
    env.pop(t.env, None)  # the benchmark's own iteration count
    subprocess.run(["perf", "record", "-q", "-e", "cpu-clock", "-F", "2000", "-o", data, "--", "taskset", "-c",
                    str(cpu), bench, f"--benchmark_filter={t.filter}", "--benchmark_repetitions=3",
                    "--benchmark_report_aggregates_only=true", f"--benchmark_out={out}",
                    "--benchmark_out_format=json"], env=env, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    report = run(["perf", "report", "-i", data, "--no-children", "--stdio", "--sort", "sym", "--percent-limit",
                  "0.01"])
    with open(out) as f:
        return report, median_ns_per_pixel(f.read(), t.width * t.height)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("benchmark", help="path of upsample_benchmark or phlm_bench (a release build)")
    ap.add_argument("methods", nargs="+", help="upsample_benchmark: spatial, temporal, herzog, drobot, taau; "
                    "phlm_bench: " + ", ".join(PHLM))
    ap.add_argument("--scale", type=int, choices=(1, 4), default=1,
                    help="upsample_benchmark: 1: 1280x1024 (default), 4: 320x256")
    ap.add_argument("--cpu", default="znver3", help="llvm-mca -mcpu (default znver3, the build VM's Zen 3)")
    ap.add_argument("--isa", default="v3", help="TEMPORAL_ISA of the run (default v3: AVX2/FMA)")
    ap.add_argument("--top", type=int, default=8, help="functions listed per method")
    ap.add_argument("--keep", help="folder for the callgrind (and perf) files (default: a temporary folder)")
    ap.add_argument("--reuse", action="store_true",
                    help="read the callgrind files a run with the same --keep folder left there instead of running "
                         "valgrind again (another --cpu model over the same counts)")
    ap.add_argument("--perf", action="store_true",
                    help="also time each function: one more run, one CPU, under perf's software clock")
    ap.add_argument("--ghz", type=float,
                    help="with --perf: the core's clock in GHz for the efficiency floor / (time x clock); the "
                         "highest clock it runs at makes the efficiency a lower bound")
    a = ap.parse_args()
    tools = ("valgrind", "objdump", "llvm-mca") + (("perf", "taskset") if a.perf else ())
    for tool in tools:
        if not shutil.which(tool):
            sys.exit(f"port_floor: {tool} not found: install it (Debian: apt-get install valgrind binutils llvm "
                     "linux-perf util-linux)")
    if a.perf and not a.ghz:
        sys.exit("port_floor: --perf needs --ghz (the core's clock, for the efficiency)")
    bench = os.path.realpath(a.benchmark)
    if not os.access(bench, os.X_OK):
        sys.exit(f"port_floor: {a.benchmark}: not an executable: build the `ci` preset's benchmarks first")
    text = disassemble(bench)
    width = DISPATCH_WIDTH.get(a.cpu, 6)
    if a.reuse and not a.keep:
        sys.exit("port_floor: --reuse needs --keep FOLDER (where the callgrind files are)")
    folder = a.keep or tempfile.mkdtemp(prefix="port_floor_")
    os.makedirs(folder, exist_ok=True)
    summary = []
    for name in a.methods:
        t = target(bench, name, a.scale)
        # Two runs, 1 and 3 timed frames after the same warm-up: the difference is two frames in the steady state,
        # without the set-up (the inputs, the state's first allocation) that both runs share.
        runs = []
        for n in (1, 3):
            out = os.path.join(folder, f"callgrind.{name}.{a.scale}.{n}")
            if a.reuse:
                if not os.path.isfile(out):
                    sys.exit(f"port_floor: {out}: not found: run once with --keep {folder} and without --reuse")
                runs.append(read_callgrind(out, bench, t.root))
                continue
            env = dict(os.environ, TEMPORAL_ISA=a.isa)
            env[t.env] = str(n)
            subprocess.run(["valgrind", "--tool=callgrind", "--dump-instr=yes", "--compress-strings=no",
                            "--compress-pos=no", f"--callgrind-out-file={out}", bench,
                            f"--benchmark_filter={t.filter}"], env=env, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            runs.append(read_callgrind(out, bench, t.root))
        (c1, _, n1), (c3, callees, n3) = runs
        calls = n3 - n1
        if calls <= 0:
            sys.exit(f"port_floor: {folder}: no call of {t.root} recorded")
        counts = {}
        for f, d in c3.items():
            diff = {x: c - c1.get(f, {}).get(x, 0) for x, c in d.items()}
            counts[f] = {x: c for x, c in diff.items() if c > 0}
        pixels = float(calls) * t.width * t.height
        inside = reachable(callees, t.root)
        pressure = unit_pressure({text.get(x, "nop") for f in inside for x in counts.get(f, {})}, a.cpu)
        rows = []
        total = collections.Counter()
        unmapped = 0
        for f in inside:
            if f not in counts:
                continue
            busy = collections.Counter()
            n = 0
            for addr, c in counts[f].items():
                n += c
                t_ = text.get(addr)
                if t_ is None:
                    unmapped += c
                    continue
                for g, v in pressure[t_].items():
                    busy[g] += c * v
            busy["dispatch"] = n / width
            g, floor = max(busy.items(), key=lambda kv: kv[1])
            rows.append((floor / pixels, n / pixels, g, f))
            total["floor"] += floor
            total["instructions"] += n
            for k, v in busy.items():
                total[k] += v
        if unmapped > 0.01 * total["instructions"]:
            print(f"port_floor: warning: {unmapped / total['instructions']:.1%} of the instructions are not in "
                  f"{bench}'s disassembly (another build?)", file=sys.stderr)
        rows.sort(reverse=True)
        times, coverage, ns_px = {}, 0.0, None
        if a.perf:
            report, ns_px = measure(bench, t, a.isa, folder)
            times, coverage = function_times(read_perf_report(report), {f for _, _, _, f in rows}, ns_px)
        # The instruction-set copies that ran (temporal/core/isa.h: namespaces v2, v3, v4): TEMPORAL_ISA=v4 on a CPU
        # without AVX-512 runs v3.
        copies = sorted({m.group(1) for f in inside if f in counts for m in re.finditer(r"::(v[234])::", f)})
        print(f"\n{name}: {calls} frames of {t.width}x{t.height} (steady state), TEMPORAL_ISA={a.isa} (copies run: "
              f"{', '.join(copies) or 'none'}), llvm-mca -mcpu={a.cpu}")
        extra = f" {'ns/px':>6} {'eff >=':>6}" if a.perf else ""
        print(f"  {'cycles/px':>9} {'instr/px':>8}{extra}  {'bound by':<26} function")
        for floor, n, g, f in rows[: a.top]:
            x = ""
            if a.perf:
                ns = times.get(f, 0.0)
                x = f" {ns:6.2f} {floor / (ns * a.ghz):6.0%}" if ns > 0 else f" {'-':>6} {'-':>6}"
            print(f"  {floor:9.2f} {n:8.2f}{x}  {g:<26} {f[-90:]}")
        x = ""
        if a.perf:
            x = f" {ns_px:6.2f} {total['floor'] / pixels / (ns_px * a.ghz):6.0%}"
        print(f"  {total['floor'] / pixels:9.2f} {total['instructions'] / pixels:8.2f}{x}  (sum over the functions "
              f"inside {t.root}, each at its own floor)")
        groups = "; ".join(f"{g} {total[g] / pixels:.2f}" for g, _ in GROUPS)
        print(f"  busy cycles per pixel by unit group: {groups}; dispatch {total['dispatch'] / pixels:.2f}")
        if a.perf:
            print(f"  timed: {t.filter} on one CPU, median of 3, {ns_px:.2f} ns/px; the functions above hold "
                  f"{coverage:.0%} of its user-space samples (the rest: set-up outside {t.root}); efficiency at "
                  f"{a.ghz:g} GHz")
        summary.append((name, total["floor"] / pixels, total["instructions"] / pixels, ns_px))
    if len(summary) > 1:
        base = summary[0]
        print(f"\nagainst {base[0]}:")
        for name, fl, n, ns in summary:
            x = f", {ns:6.2f} ns/px ({ns / base[3]:.2f}x)" if ns else ""
            print(f"  {name:<16} floor {fl:6.2f} cycles/px ({fl / base[1]:.2f}x), {n:6.2f} instructions/px "
                  f"({n / base[2]:.2f}x){x}")
    if not a.keep:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
