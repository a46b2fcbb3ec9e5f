#include "method_list.h"

#include <cstdio>
#include <iostream>

namespace temporal::tool {
namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", unsigned(c));
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string json_strings(const std::vector<std::string>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + json_string(v[i]);
  return out + "]";
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& a : v) s += (s.empty() ? "" : " ") + a;
  return s;
}

}  // namespace

std::string method_list_text(const std::vector<MethodRow>& rows, const std::vector<SuffixRow>& suffixes) {
  std::string out;
  for (const MethodRow& r : rows) {
    std::vector<std::string> args = {"--method", r.variant.method};
    args.insert(args.end(), r.variant.args.begin(), r.variant.args.end());
    std::string devices;
    for (const auto& d : r.implementations) devices += (devices.empty() ? "" : ",") + d;
    out += r.variant.name + "\t" + joined(args) + "\t" + r.variant.summary + "\t" + devices + "\n";
  }
  for (const SuffixRow& s : suffixes) out += "*" + s.suffix + "\t" + joined(s.args) + "\t" + s.summary + "\n";
  return out;
}

std::string method_list_json(const std::vector<MethodRow>& rows, const std::vector<SuffixRow>& suffixes) {
  std::string out = "[";
  const char* sep = "\n  ";
  for (const MethodRow& r : rows) {
    out += sep;
    out += "{\"name\": " + json_string(r.variant.name) + ", \"method\": " + json_string(r.variant.method) +
           ", \"args\": " + json_strings(r.variant.args) + ", \"summary\": " + json_string(r.variant.summary) +
           ", \"stateful\": " + (r.stateful ? "true" : "false") +
           ", \"implementations\": " + json_strings(r.implementations);
    if (r.latency_frames) out += ", \"latency_frames\": " + std::to_string(*r.latency_frames);
    out += "}";
    sep = ",\n  ";
  }
  for (const SuffixRow& s : suffixes) {
    out += sep;
    out += "{\"suffix\": " + json_string(s.suffix) + ", \"args\": " + json_strings(s.args) +
           ", \"summary\": " + json_string(s.summary) + "}";
    sep = ",\n  ";
  }
  return out + "\n]\n";
}

void add_method_lists(Tool& tool, std::vector<MethodRow> rows, std::vector<SuffixRow> suffixes) {
  const std::string text = method_list_text(rows, suffixes);
  const std::string json = method_list_json(rows, suffixes);
  tool.app().add_flag_callback(
      "--list-methods",
      [text] {
        std::cout << text;
        throw CLI::Success();
      },
      "Print every method and named variant (name, arguments, summary, devices; tab-separated, one per line) and "
      "exit");
  tool.app().add_flag_callback(
      "--list-methods-json",
      [json] {
        std::cout << json;
        throw CLI::Success();
      },
      "Print the methods as JSON (name, method, args, summary, stateful, implementations) and exit");
}

}  // namespace temporal::tool
