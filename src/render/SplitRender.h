// One render split over several executors at once (a node's GPUs): each takes a contiguous
// share of the sample sequence on a thread of its own, and their films add up as a cluster's
// shares do (envgi.distributed), so the image is the one render's up to float rounding.
#pragma once

#include <functional>

#include "render/Renderer.h"

namespace envgi {

// Makes executor `index` for the share that opts names (firstSample, sampleEnd). Called on the
// thread that then runs that share, so a GPU's device can be made current there.
using SharePreparer = std::function<PreparedRender(const RenderOptions& opts, int index)>;

// Renders samples [opts.firstSample, opts.sampleEnd or spp) of `spp` in `shares` nearly equal
// shares at once. Each share runs without a bar and without checkpoints; Ctrl-C (opts.cancel)
// stops every share, and the image is then each pixel's mean over the samples it took. Path
// and direct only, as for any share (requireShareable), and no variance out.
Image renderSplit(int width, int height, int spp, int shares, const RenderOptions& opts,
                  const SharePreparer& prepare, RenderStats* stats);

}  // namespace envgi
