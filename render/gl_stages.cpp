// The GL stages of the pipeline: render the virtual layer (EGL, GLES 3) and composite it over the
// camera frame into ctx.output (RGB24). Both share one GL context, created on the calling thread.
#include "render/gl_stages.h"

#include "render/composite_stage.h"
#include "render/render_session.h"
#include "render/render_stage.h"

namespace arpipe {

std::vector<std::unique_ptr<Stage>> make_gl_stages() {
  auto session = std::make_shared<RenderSession>();
  std::vector<std::unique_ptr<Stage>> stages;
  stages.push_back(std::make_unique<RenderStage>(session));
  stages.push_back(std::make_unique<CompositeStage>(session));
  return stages;
}

}  // namespace arpipe
