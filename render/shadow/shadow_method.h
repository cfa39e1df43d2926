// The shadow-map filters: the enum and its names live in core/config/shadow_method.h, so the
// config holds the typed value.
#pragma once

#include "core/config/shadow_method.h"
