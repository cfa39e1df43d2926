#include "capture/sinks/http/prometheus_writer.h"

#include <cmath>

#include <fmt/format.h>

namespace arpipe {

namespace {

std::string number(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  return fmt::format("{}", value);  // shortest text that reads back exactly
}

std::string label_text(const PrometheusLabels& labels) {
  if (labels.empty()) return {};
  std::string out = "{";
  for (size_t i = 0; i < labels.size(); ++i)
    out += fmt::format("{}{}=\"{}\"", i ? "," : "", labels[i].first, prometheus_label_value(labels[i].second));
  return out + "}";
}

}  // namespace

std::string prometheus_label_value(std::string_view value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\') out += "\\\\";
    else if (c == '"') out += "\\\"";
    else if (c == '\n') out += "\\n";
    else out += c;
  }
  return out;
}

void PrometheusWriter::family(std::string_view name, std::string_view type, std::string_view help) {
  // HELP text escapes backslash and newline only.
  std::string escaped;
  for (const char c : help) escaped += c == '\\' ? std::string("\\\\") : c == '\n' ? std::string("\\n") : std::string(1, c);
  text_ += fmt::format("# HELP {} {}\n# TYPE {} {}\n", name, escaped, name, type);
}

void PrometheusWriter::sample(std::string_view name, const PrometheusLabels& labels, double value) {
  text_ += fmt::format("{}{} {}\n", name, label_text(labels), number(value));
}

void PrometheusWriter::histogram(std::string_view name, const PrometheusLabels& labels, const LatencyHistogram& h) {
  for (size_t i = 0; i <= LatencyHistogram::kBounds.size(); ++i) {
    PrometheusLabels with_le = labels;
    with_le.emplace_back("le", i < LatencyHistogram::kBounds.size() ? number(LatencyHistogram::kBounds[i]) : "+Inf");
    sample(fmt::format("{}_bucket", name), with_le, double(h.cumulative(i)));
  }
  sample(fmt::format("{}_sum", name), labels, h.sum());
  sample(fmt::format("{}_count", name), labels, double(h.count()));
}

}  // namespace arpipe
