// Per-shard comparisons merged into one (temporal/compare/comparison.h, read_comparison_csv and
// merge_comparisons): a long sequence compared as several frame ranges on different machines gives exactly the
// single run's per-frame values (each shard primes its first frame's flicker from the frame before it, and the
// CSV stores every value so that it reads back as the same double), hence exactly its means and intervals.
#include "temporal/compare/comparison.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace temporal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One CSV record (RFC 4180 quoting, as write_comparison_csv writes it).
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cur += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cur += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

bool parse_number(const std::string& text, double& v) {
  if (text.empty()) {
    v = kNaN;
    return true;
  }
  if (text == "inf" || text == "-inf") {
    v = text[0] == '-' ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    return true;
  }
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

// Where a CSV column goes in FrameMetrics.
struct Slot {
  enum Kind { Frame, Sequence, Region, RegionShare, Value, Inside, Outside, Peak, Valid, NonfiniteTest, NonfiniteRef, Compute, MetricsMs, MaskFraction, Unknown };
  Kind kind = Unknown;
  std::string metric;
  std::size_t column = 0;
};

Slot slot_of(const std::string& header) {
  static const std::map<std::string, Slot::Kind> fixed = {
      {"frame", Slot::Frame},          {"sequence", Slot::Sequence},          {"peak", Slot::Peak},
      {"valid_pixels", Slot::Valid},   {"nonfinite_test", Slot::NonfiniteTest}, {"nonfinite_reference", Slot::NonfiniteRef},
      {"compute_ms", Slot::Compute},   {"metrics_ms", Slot::MetricsMs},       {"mask_fraction", Slot::MaskFraction},
      {"region", Slot::Region},        {"region_share", Slot::RegionShare}};
  if (auto it = fixed.find(header); it != fixed.end()) return {it->second, {}, 0};
  for (const auto& d : metric_registry()) {
    for (std::size_t k = 0; k < d.columns.size(); ++k)
      if (d.columns[k].csv == header) return {Slot::Value, d.name, k};
    if (d.mask_columns[0] == header) return {Slot::Inside, d.name, 0};
    if (d.mask_columns[1] == header) return {Slot::Outside, d.name, 0};
  }
  return {};
}

}  // namespace

Expected<ComparisonReport> read_comparison_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error::input(path, "cannot read this CSV (does it exist?)");
  std::string line;
  if (!std::getline(in, line)) return Error::input(path, "is empty: not a CSV written by compare --csv");
  const auto headers = split_csv(line);
  std::vector<Slot> slots;
  for (const auto& h : headers) {
    slots.push_back(slot_of(h));
    if (slots.back().kind == Slot::Unknown)
      return Error::input(path, "column '" + h + "' is not one compare writes: merge CSVs written by compare --csv");
  }
  if (headers.size() < 2 || slots[0].kind != Slot::Frame || slots[1].kind != Slot::Sequence)
    return Error::input(path, "does not start with frame,sequence: not a CSV written by compare --csv");
  ComparisonReport report;
  for (const auto& s : slots)
    if (s.kind == Slot::Value && std::find(report.metrics.begin(), report.metrics.end(), s.metric) == report.metrics.end())
      report.metrics.push_back(s.metric);
  for (const auto& s : slots) {
    if (s.kind == Slot::MaskFraction) report.mask = "(merged)";
    if (s.kind == Slot::Region) report.regions = true;
  }
  std::map<std::string, std::size_t> index;  // sequence name -> report.sequences position
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    const auto cells = split_csv(line);
    if (cells.size() != headers.size())
      return Error::input(path, "row " + std::to_string(row) + " has " + std::to_string(cells.size()) + " fields, the header " +
                                    std::to_string(headers.size()));
    FrameMetrics f;
    std::string name;
    int region = kAllRegions;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const Slot& s = slots[c];
      if (s.kind == Slot::Sequence) {
        name = cells[c];
        continue;
      }
      if (s.kind == Slot::Region) {
        for (int r = 0; r < kRegionCount; ++r)
          if (cells[c] == region_name(r)) region = r;
        if (region == kAllRegions && cells[c] != "all")
          return Error::input(path, "row " + std::to_string(row) + ": region '" + cells[c] +
                                        "' is not all, static, moving or disoccluded");
        continue;
      }
      double v = 0.0;
      if (!parse_number(cells[c], v))
        return Error::input(path, "row " + std::to_string(row) + ", column " + headers[c] + ": '" + cells[c] + "' is not a number");
      switch (s.kind) {
        case Slot::Frame: f.frame = int(v); break;
        case Slot::Value: {
          MetricSample& m = f.ensure_sample(s.metric);
          if (m.values.size() <= s.column) m.values.resize(s.column + 1, kNaN);
          m.values[s.column] = v;
          break;
        }
        case Slot::Inside: f.ensure_sample(s.metric).inside = v; break;
        case Slot::Outside: f.ensure_sample(s.metric).outside = v; break;
        case Slot::Peak: f.peak = v; break;
        case Slot::Valid: if (!std::isnan(v)) f.valid_pixels = std::size_t(v); break;
        case Slot::NonfiniteTest: if (!std::isnan(v)) f.nonfinite_test = std::size_t(v); break;
        case Slot::NonfiniteRef: if (!std::isnan(v)) f.nonfinite_reference = std::size_t(v); break;
        case Slot::Compute: if (!std::isnan(v)) f.compute_ms = v; break;
        case Slot::MetricsMs: f.metrics_ms = std::isnan(v) ? 0.0 : v; break;
        case Slot::MaskFraction: f.has_mask = true; f.mask_fraction = v; break;
        default: break;
      }
    }
    if (region != kAllRegions) {
      // A region row belongs to the `all` row of its sequence and frame written before it.
      const auto at = index.find(name);
      FrameMetrics* whole = nullptr;
      if (at != index.end())
        for (auto& g : report.sequences[at->second].frames)
          if (g.frame == f.frame) whole = &g;
      if (!whole)
        return Error::input(path, "row " + std::to_string(row) + ": a " + region_name(region) +
                                      " row without the `all` row of its frame and sequence before it");
      whole->has_regions = true;
      whole->region_pixels[std::size_t(region)] = f.valid_pixels;
      for (const auto& sample : f.metrics)
        whole->ensure_sample(sample.metric).regions[std::size_t(region)] =
            sample.values.empty() ? kNaN : sample.values.front();
      continue;
    }
    auto it = index.find(name);
    if (it == index.end()) {
      it = index.emplace(name, report.sequences.size()).first;
      SequenceReport sequence;
      sequence.name = name;
      report.sequences.push_back(std::move(sequence));
    }
    report.sequences[it->second].frames.push_back(std::move(f));
  }
  std::set<int> frames;
  for (const auto& s : report.sequences)
    for (const auto& f : s.frames) frames.insert(f.frame);
  report.frames.assign(frames.begin(), frames.end());
  report.reference = path;
  return report;
}

Expected<ComparisonReport> merge_comparisons(const std::vector<ComparisonReport>& parts,
                                            const std::vector<std::string>& names) {
  if (parts.empty()) return Error::usage("nothing to merge: give the per-shard CSVs");
  ComparisonReport merged = parts.front();
  merged.reference = "merged:";
  for (const auto& n : names) merged.reference += " " + n;
  for (std::size_t p = 1; p < parts.size(); ++p) {
    const ComparisonReport& part = parts[p];
    const std::string& file = p < names.size() ? names[p] : std::string();
    if (part.metrics != merged.metrics)
      return Error::input(file, "measures other metrics than " + (names.empty() ? std::string("the first") : names[0]) +
                                    ": merge shards of one comparison (same compare options)");
    if (part.regions != merged.regions)
      return Error::input(file, std::string(part.regions ? "has" : "has no") + " region rows where the first shard " +
                                    (merged.regions ? "has" : "has none") + ": give every shard the same --regions");
    if (part.sequences.size() != merged.sequences.size())
      return Error::input(file, "has " + std::to_string(part.sequences.size()) + " sequences, the first shard " +
                                    std::to_string(merged.sequences.size()));
    for (std::size_t s = 0; s < part.sequences.size(); ++s) {
      if (part.sequences[s].name != merged.sequences[s].name)
        return Error::input(file, "sequence '" + part.sequences[s].name + "' where the first shard has '" +
                                      merged.sequences[s].name + "' (same --names, same order)");
      auto& dst = merged.sequences[s].frames;
      dst.insert(dst.end(), part.sequences[s].frames.begin(), part.sequences[s].frames.end());
    }
  }
  std::set<int> all;
  for (auto& s : merged.sequences) {
    std::stable_sort(s.frames.begin(), s.frames.end(),
                     [](const FrameMetrics& a, const FrameMetrics& b) { return a.frame < b.frame; });
    for (std::size_t i = 1; i < s.frames.size(); ++i)
      if (s.frames[i].frame == s.frames[i - 1].frame)
        return Error::input({}, "frame " + std::to_string(s.frames[i].frame) + " of '" + s.name +
                                    "' is in two shards: the shards' --frames ranges must not overlap");
    for (const auto& f : s.frames) all.insert(f.frame);
  }
  merged.frames.assign(all.begin(), all.end());
  return merged;
}

Expected<ComparisonReport> merge_comparison_csvs(const std::vector<std::string>& csvs, const ComparisonSetup& setup) {
  std::vector<ComparisonReport> parts;
  for (const auto& path : csvs) {
    auto r = read_comparison_csv(path);
    if (!r) return r.error();
    parts.push_back(std::move(*r));
  }
  auto merged = merge_comparisons(parts, csvs);
  if (!merged) return merged;
  merged->warmup_frames = setup.warmup_frames;
  // The CSV does not carry the compared layers: the merge's own options name them (the shards' must be the same).
  merged->layer = setup.layer;
  merged->reference_layer = setup.reference_layer.empty() ? setup.layer : setup.reference_layer;
  merged->bootstrap = setup.bootstrap;
  merged->speed_metric = setup.speed_metric;
  merged->region_options = setup.region_options;  // not in the CSV: the merge's own options name them
  return merged;
}

}  // namespace temporal
