#!/usr/bin/env python3
"""port_floor.py's callgrind reader on a hand-written file (no valgrind, objdump or llvm-mca needed): the counts it
reads are the numbers every floor is made of, and the format has traps (the cost line after `calls=` is a call's
inclusive cost, not an instruction; lines of other objects; the same function under several mangled spellings)."""
import os
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import port_floor  # noqa: E402

BINARY = "/opt/bench/upsample_benchmark"

# Two frames' worth: main -> BM_PerPixel -> Upsampler::process (called twice) -> a row kernel (a clone and a
# lambda of it), plus a libm function inside the process and make_frame outside it.
CALLGRIND = f"""# callgrind format
version: 1
creator: callgrind-3.19.0
positions: instr line
events: Ir
summary: 1000

ob={BINARY}
fl=/src/bench.cpp
fn=(anonymous namespace)::BM_PerPixel(benchmark::State&)
0x1000 10 5
cob={BINARY}
cfl=/src/upsampler.cpp
cfn=temporal::upsample::Upsampler::process(temporal::Image const&, temporal::Image const&, bool)
calls=2 0x2000 20
0x1004 11 900
0x1008 12 1
cfn=temporal::test::make_frame(temporal::test::SyntheticScene const&, int)
calls=1 0x5000 50
0x100c 13 400

fn=temporal::upsample::Upsampler::process(temporal::Image const&, temporal::Image const&, bool)
0x2000 20 2
0x2004 21 2
cfn=temporal::upsample::(anonymous namespace)::v3::kernel_row(int, float const*) [clone .isra.0]
calls=4 0x3000 30
0x2008 22 800
cob=/usr/lib/x86_64-linux-gnu/libm.so.6
cfn=__cosf_fma
calls=2 0x9000 0
0x200c 23 60

fn=temporal::upsample::(anonymous namespace)::v3::kernel_row(int, float const*) [clone .isra.0]
0x3000 30 300
0x3004 31 300
0x3000 30 100
cfn=temporal::upsample::(anonymous namespace)::v3::kernel_row(int, float const*)::{{lambda(int)#1}}::operator()(int) const
calls=8 0x3100 40
0x3008 32 96

fn=temporal::upsample::(anonymous namespace)::v3::kernel_row(int, float const*)::{{lambda(int)#1}}::operator()(int) const
0x3100 40 96

fn=temporal::test::make_frame(temporal::test::SyntheticScene const&, int)
0x5000 50 400

ob=/usr/lib/x86_64-linux-gnu/libm.so.6
fn=__cosf_fma
0x9000 0 60
"""


class ReadCallgrind(unittest.TestCase):
    def setUp(self):
        fd, self.path = tempfile.mkstemp(suffix=".callgrind")
        with os.fdopen(fd, "w") as f:
            f.write(CALLGRIND)
        self.counts, self.callees, self.calls = port_floor.read_callgrind(self.path, BINARY)

    def tearDown(self):
        os.unlink(self.path)

    def test_counts_calls_of_process(self):
        self.assertEqual(self.calls, 2)

    def test_the_line_after_calls_is_not_an_instruction(self):
        # process: 0x2000 and 0x2004 (2 each); 0x2008 (800) and 0x200c (60) are the calls' inclusive costs.
        self.assertEqual(dict(self.counts["temporal::upsample::Upsampler::process"]), {0x2000: 2, 0x2004: 2})

    def test_repeated_addresses_add_up_and_clones_merge(self):
        row = self.counts["temporal::upsample::::v3::kernel_row"]
        self.assertEqual(dict(row), {0x3000: 400, 0x3004: 300})

    def test_lambdas_stay_apart_from_their_function(self):
        lam = "temporal::upsample::::v3::kernel_row::{lambda#1}::operator"
        self.assertEqual(dict(self.counts[lam]), {0x3100: 96})

    def test_other_objects_are_not_counted(self):
        self.assertNotIn("__cosf_fma", self.counts)

    def test_reachable_from_process_only(self):
        inside = port_floor.reachable(self.callees, "Upsampler::process")
        self.assertIn("temporal::upsample::::v3::kernel_row", inside)
        self.assertIn("temporal::upsample::::v3::kernel_row::{lambda#1}::operator", inside)
        self.assertIn("__cosf_fma", inside)
        self.assertNotIn("temporal::test::make_frame", inside)
        self.assertNotIn("::BM_PerPixel", inside)


class Normalise(unittest.TestCase):
    def test_arguments_clones_and_const_go(self):
        self.assertEqual(port_floor.normalise("a::f(int, float const*) const [clone .constprop.0]"), "a::f")
        self.assertEqual(port_floor.normalise("a::(anonymous namespace)::v3::h(int)"), "a::::v3::h")

    def test_return_types_go(self):
        # callgrind names template instances with their return type; perf does too, but not every function.
        self.assertEqual(port_floor.normalise("void a::g<8>(int (*)(int), std::span<float const>)"), "a::g<8>")
        self.assertEqual(port_floor.normalise("int r::run<true, true, 4, true>(float const*, int)"),
                         "r::run<true, true, 4, true>")
        self.assertEqual(port_floor.normalise("unsigned long a::n()"), "a::n")
        self.assertEqual(port_floor.normalise("a::f::{lambda(int, int)#1}::operator()(int, int) const"),
                         "a::f::{lambda#1}::operator")


# `perf report --no-children --stdio --sort sym` of a one-thread run: two functions inside the method (one listed
# twice, under two clones), set-up outside it, a kernel line.
PERF_REPORT = """# Samples: 1K of event 'cpu-clock'
#
# Overhead  Symbol
# ........  ......
#
    50.00%  [.] int temporal::upsample::(anonymous namespace)::v3::kernel_row(int, float const*)
    10.00%  [.] temporal::upsample::(anonymous namespace)::v3::kernel_row(int, float const*) [clone .isra.0]
    20.00%  [.] temporal::upsample::Upsampler::process(temporal::Image const&, temporal::Image const&, bool)
    15.00%  [.] temporal::test::make_frame(temporal::test::SyntheticScene const&, int)
     5.00%  [k] clear_page_erms
"""


class PerfJoin(unittest.TestCase):
    def test_shares_by_normalised_name_without_the_kernel(self):
        shares = port_floor.read_perf_report(PERF_REPORT)
        self.assertAlmostEqual(shares["temporal::upsample::::v3::kernel_row"], 60.0)
        self.assertAlmostEqual(shares["temporal::upsample::Upsampler::process"], 20.0)
        self.assertNotIn("clear_page_erms", shares)
        self.assertAlmostEqual(sum(shares.values()), 95.0)

    def test_measured_time_split_over_the_functions_inside(self):
        inside = {"temporal::upsample::::v3::kernel_row", "temporal::upsample::Upsampler::process"}
        times, coverage = port_floor.function_times(port_floor.read_perf_report(PERF_REPORT), inside, 8.0)
        # 60 and 20 of the 80 % inside: 3/4 and 1/4 of 8 ns; the set-up (15 %) is not the method's time.
        self.assertAlmostEqual(times["temporal::upsample::::v3::kernel_row"], 6.0)
        self.assertAlmostEqual(times["temporal::upsample::Upsampler::process"], 2.0)
        self.assertNotIn("temporal::test::make_frame", times)
        self.assertAlmostEqual(coverage, 80.0 / 95.0)

    def test_median_time_per_pixel_from_the_benchmark_json(self):
        doc = """{"benchmarks": [
          {"name": "BM_PerPixel/2/1/real_time", "run_type": "iteration", "real_time": 9.0, "time_unit": "ms"},
          {"name": "BM_PerPixel/2/1/real_time_mean", "run_type": "aggregate", "aggregate_name": "mean",
           "real_time": 8.0, "time_unit": "ms"},
          {"name": "BM_PerPixel/2/1/real_time_median", "run_type": "aggregate", "aggregate_name": "median",
           "real_time": 6.5536, "time_unit": "ms"}]}"""
        self.assertAlmostEqual(port_floor.median_ns_per_pixel(doc, 1280 * 1024), 5.0)


class Frames(unittest.TestCase):
    def test_calls_of_another_root(self):
        # phlm_bench's frames are calls of PhlmFilter::process: none in the upsampling file.
        fd, path = tempfile.mkstemp(suffix=".callgrind")
        with os.fdopen(fd, "w") as f:
            f.write(CALLGRIND.replace("temporal::upsample::Upsampler::process", "temporal::phlm::PhlmFilter::process"))
        try:
            _, callees, calls = port_floor.read_callgrind(path, BINARY, "PhlmFilter::process")
            self.assertEqual(calls, 2)
            self.assertEqual(port_floor.read_callgrind(path, BINARY)[2], 0)
            self.assertIn("temporal::upsample::::v3::kernel_row", port_floor.reachable(callees, "PhlmFilter::process"))
        finally:
            os.unlink(path)


if __name__ == "__main__":
    unittest.main()
