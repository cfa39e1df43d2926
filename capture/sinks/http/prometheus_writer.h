// Writes Prometheus' text exposition format 0.0.4: one HELP and TYPE line per metric family, then
// its samples, label values escaped, histograms as cumulative buckets with +Inf, _sum and _count.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/pipeline/latency_histogram.h"

namespace arpipe {

using PrometheusLabels = std::vector<std::pair<std::string_view, std::string>>;

class PrometheusWriter {
 public:
  // Starts a family; type is "counter", "gauge" or "histogram". A family's samples follow its start.
  void family(std::string_view name, std::string_view type, std::string_view help);
  void sample(std::string_view name, const PrometheusLabels& labels, double value);
  void sample(std::string_view name, double value) { sample(name, {}, value); }
  // The samples of one histogram of family `name` (name_bucket, name_sum, name_count).
  void histogram(std::string_view name, const PrometheusLabels& labels, const LatencyHistogram& h);
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

// A label value as the format wants it: backslash, double quote and newline escaped.
std::string prometheus_label_value(std::string_view value);

}  // namespace arpipe
