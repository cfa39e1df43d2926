// Something built once per camera model (a lens warp map, an undistortion) and kept while frames
// keep coming with that model: found by pointer first, then by value, never rebuilt per frame.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "core/geometry/camera_model.h"
#include "render/gl/render_errors.h"

namespace arpipe {

template <typename T>
class PerModelCache {
 public:
  // The value built by build(model) for this model, or for the last model when it is the same
  // (same pointer, or same lens model, intrinsics and size). A build that threw is remembered as
  // well and its RenderError thrown again, so a lens that cannot be used costs one build, not one
  // per frame.
  template <typename Build>
  std::shared_ptr<const T> get(const std::shared_ptr<const CameraModel>& model, Build&& build) {
    if (!model) throw RenderError("the frame has no camera model");
    if (model != model_ && !(model_ && same_lens(*model, *model_))) {
      value_.reset();
      error_.clear();
      try {
        value_ = std::make_shared<const T>(build(*model));
      } catch (const std::exception& e) {
        error_ = e.what();
      }
    }
    model_ = model;
    if (!value_) throw RenderError(error_);
    return value_;
  }

  // Forgets the value, for when what build() depends on besides the model has changed.
  void clear() {
    model_.reset();
    value_.reset();
    error_.clear();
  }

 private:
  static bool same_lens(const CameraModel& a, const CameraModel& b) {
    return a.lensmodel() == b.lensmodel() && a.intrinsics() == b.intrinsics() && a.width() == b.width() &&
           a.height() == b.height();
  }

  std::shared_ptr<const CameraModel> model_;
  std::shared_ptr<const T> value_;
  std::string error_;
};

}  // namespace arpipe
