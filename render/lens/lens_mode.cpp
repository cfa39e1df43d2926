// The three ways the virtual layer can match the real lens (config key render.lens), and which
// lens models each of them can reproduce, checked before streaming starts.
#include "render/lens/lens_mode.h"

#include <fmt/format.h>

#include "core/config/config.h"
#include "render/lens/lens_projection.h"
#include "render/lens/lens_undistortion.h"
#include "render/lens/lens_warp_map.h"

namespace arpipe {

void check_lens_for_mode(const CameraModel& model, LensMode mode) {
  switch (mode) {
    case LensMode::Map: check_lens_warpable(model); return;
    case LensMode::Vertex: check_lens_model_supported(model); return;
    case LensMode::Undistort: check_lens_undistortable(model); return;
  }
}

}  // namespace arpipe
