// PRT transfer vectors: kind names and per-vertex access.
#include "render/prt/prt_transfer.h"

namespace arpipe {

std::optional<TransferKind> parse_transfer_kind(std::string_view name) {
  if (name == "unshadowed") return TransferKind::Unshadowed;
  if (name == "shadowed") return TransferKind::Shadowed;
  if (name == "interreflected") return TransferKind::Interreflected;
  return std::nullopt;
}

std::string_view transfer_kind_name(TransferKind kind) {
  switch (kind) {
    case TransferKind::Unshadowed:
      return "unshadowed";
    case TransferKind::Shadowed:
      return "shadowed";
    case TransferKind::Interreflected:
      return "interreflected";
  }
  return "unknown";
}

size_t PrtTransfer::vertex_count() const {
  const auto per_vertex = size_t(bands) * size_t(bands);
  return per_vertex == 0 ? 0 : coefficients.size() / per_vertex;
}

std::span<const float> PrtTransfer::at(size_t vertex) const {
  const auto per_vertex = size_t(bands) * size_t(bands);
  return std::span<const float>(coefficients).subspan(vertex * per_vertex, per_vertex);
}

}  // namespace arpipe
