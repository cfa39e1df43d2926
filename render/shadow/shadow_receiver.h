// The shadow catcher: the patch of real ground under the virtual objects on which their shadows
// fall, drawn into the virtual layer as a darkening of the camera frame (object_renderer.h).
#pragma once

#include <memory>

#include "render/uploaded_objects.h"
#include "render/shadow/shadow_frustum.h"

namespace arpipe {

class ShadowReceiver {
 public:
  // Uploads the square, its sides split in subdivisions (for a lens applied per vertex, else 1);
  // needs a current context.
  explicit ShadowReceiver(int subdivisions);
  int subdivisions() const { return subdivisions_; }
  // The catcher over this patch (a square covering it), valid until the next call.
  const UploadedObject& over(const ReceiverPatch& patch);

 private:
  UploadedObject object_;
  int subdivisions_ = 1;
};

}  // namespace arpipe
