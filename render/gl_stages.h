// The GL stages of the pipeline: render the virtual layer (EGL, GLES 3) and composite it over the
// camera frame into ctx.output (RGB24). Both share one GL context, created on the calling thread.
#pragma once

#include <memory>
#include <vector>

#include "core/pipeline/stage.h"

namespace arpipe {

// Returns {render, composite}. The render stage's first configure() creates the GL context on the
// calling thread, so configure and process both stages on the processing thread, in this order.
std::vector<std::unique_ptr<Stage>> make_gl_stages();

}  // namespace arpipe
