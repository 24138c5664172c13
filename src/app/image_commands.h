// The commands that read finished images: compare and preview (main.cpp dispatches to them).
#pragma once

#include "options/options.h"

namespace pb {

// `photonbound compare RENDER REFERENCE [--json]`: the figures of compare.h on stdout.
int compare_command(const CompareOptions& o);
// `photonbound preview IN.exr -o OUT.png`: an sRGB PNG of the radiance channels.
int preview_command(const PreviewOptions& o);

}  // namespace pb
