// oiio_loader.h -- the OpenImageIO module (oiio_plugin.h), loaded the first time it is asked
// for: from $MPSHADE_OIIO_PLUGIN if set, else beside the mpshade binary (a build tree), else
// in the installed library folder (lib/mpshade beside bin).
#pragma once

#include "app/oiio_plugin.h"

namespace mpshade {

// The module's interface, loaded once (thread-safe) and kept for the process. Throws
// std::runtime_error naming every place it looked when it cannot be loaded.
const MpshadeOiioPlugin& oiioPlugin();

}  // namespace mpshade
