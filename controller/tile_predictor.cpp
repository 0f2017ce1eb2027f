#include "controller/tile_predictor.h"

#include <algorithm>

namespace mpshade {

TilePredictor::TilePredictor(const MultiphaseRenderer& renderer)
    : renderer_(renderer), phase_(renderer.scene()) {}

std::vector<TileRequest> TilePredictor::predict(int frame, const RenderOptions& options,
                                                int divisor, double& seconds,
                                                std::chrono::steady_clock::time_point deadline) {
    const auto start = std::chrono::steady_clock::now();
    const Scene& scene = renderer_.scene();
    const DynamicOptions current = renderer_.dynamicOptionsFor(options);
    const ScopedSpan span(current.trace, "predict tiles", PhaseKind::Static, SpanLevel::Phase, -1,
                          frame);
    divisor = std::max(1, divisor);
    const RenderOptions full = options.resolved(scene.settings);
    const int width = std::max(1, full.width / divisor);
    const int height = std::max(1, full.height / divisor);
    const int spp = full.samplesPerPixel;
    state_ = frameStateAt(renderer_.resources(), frame, width, height, 1);
    const std::shared_ptr<const SampleLayout> layout =
        layouts_.get(width, height, 1, options.seed, options.filter);
    std::vector<const ObjectRepresentation*> drawn(scene.objects.size(), nullptr);
    for (size_t i = 0; i < drawn.size(); ++i) {
        const ObjectRepresentation* rep = renderer_.representation(i);
        if (rep && objectInView(*scene.objects[i].surface, state_.objects[i], state_.camera))
            drawn[i] = rep;
    }
    DynamicOptions o = current;
    o.trace = nullptr;
    o.reuseBytes = 0;  // a prediction is its probes' missing tiles: every point must probe
    // The same world footprint as the full image's points: a low-resolution pixel is
    // `divisor` full ones, and a per-pixel point's footprint is half a pixel.
    o.footprintScale = current.footprintScale * footprintPixels(current.shadingRate, spp) /
                       (0.5f * static_cast<float>(divisor));
    o.shadingRate = ShadingRate::Pixel;
    o.deadline = deadline;
    phase_.begin(state_, drawn, layout, o);
    // Abandoned in rasterization: no visibility to trust, so nothing predicted. In
    // shading: the finished bands' tiles stand.
    std::vector<TileRequest> missing;
    if (!phase_.abandoned()) missing = phase_.shade(true);
    abandoned_ = phase_.abandoned();
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    seconds = abandoned_ ? std::max(seconds, spent) : spent;
    return missing;
}

}  // namespace mpshade
