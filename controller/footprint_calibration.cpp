#include "controller/footprint_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "controller/multiphase_renderer.h"

namespace mpshade {

std::vector<int32_t> pixelOwners(const VisibilityBuffer& vis, size_t objects, int margin,
                                 std::vector<uint64_t>& pixels) {
    const int width = vis.width, height = vis.height;
    const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
    const size_t spp = static_cast<size_t>(vis.spp), layers = static_cast<size_t>(vis.layers);
    // Per pixel, the one object any surface of its samples belongs to: kNone, or kSeveral.
    constexpr int32_t kNone = -1, kSeveral = -2;
    std::vector<int32_t> seen(n, kNone);
    std::vector<int32_t> owners(n, -1);
    for (size_t p = 0; p < n; ++p) {
        const size_t first = p * spp;
        int32_t one = kNone;
        bool whole = true;  // every sample sees a surface, the first of one object
        for (size_t k = 0; k < spp; ++k) {
            const size_t s = first + k;
            whole =
                whole && vis.count[s] > 0 && vis.object[s * layers] == vis.object[first * layers];
            for (size_t l = 0; l < vis.count[s]; ++l) {
                const auto o = static_cast<int32_t>(vis.object[s * layers + l]);
                one = one == kNone || one == o ? o : kSeveral;
            }
        }
        seen[p] = one;
        if (whole && vis.object[first * layers] < objects)
            owners[p] = static_cast<int32_t>(vis.object[first * layers]);
    }
    // A pixel whose filter reaches another object's samples would measure that object's
    // change too (every object is searched at once).
    pixels.assign(objects, 0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const size_t p = static_cast<size_t>(y) * width + x;
            const int32_t o = owners[p];
            if (o < 0) continue;
            bool alone = true;
            for (int qy = std::max(0, y - margin); qy <= std::min(height - 1, y + margin) && alone;
                 ++qy)
                for (int qx = std::max(0, x - margin); qx <= std::min(width - 1, x + margin);
                     ++qx) {
                    const int32_t q = seen[static_cast<size_t>(qy) * width + qx];
                    if (q != kNone && q != o) {
                        alone = false;
                        break;
                    }
                }
            if (alone)
                ++pixels[static_cast<size_t>(o)];
            else
                owners[p] = -1;  // the window reads `seen`, never owners
        }
    return owners;
}

void addSampleNoise(const SampleBuffer& samples, std::span<const uint8_t> uniform,
                    std::span<const int32_t> owners, std::vector<FootprintMeasure>& measures) {
    const int spp = samples.spp;
    if (spp < 2) return;
    // The strata in a checkerboard (sample k's stratum is k % nx, k / nx: sample_pattern.cpp).
    const int nx = static_cast<int>(std::ceil(std::sqrt(static_cast<float>(spp))));
    int even = 0;
    for (int k = 0; k < spp; ++k) even += (k % nx + k / nx) % 2 == 0 ? 1 : 0;
    const int odd = spp - even;
    if (odd == 0) return;
    // Var(mean) = Var(even mean - odd mean) (1/spp) / (1/even + 1/odd) for independent samples.
    const double scale = (1.0 / spp) / (1.0 / even + 1.0 / odd);
    for (size_t p = 0; p < owners.size(); ++p) {
        const int32_t o = owners[p];
        if (o < 0 || (p < uniform.size() && uniform[p])) continue;
        const float* s = &samples.rgba[p * static_cast<size_t>(spp) * 4];
        double noise = 0.0;
        for (int c = 0; c < 3; ++c) {
            double e = 0.0, d = 0.0;
            for (int k = 0; k < spp; ++k)
                ((k % nx + k / nx) % 2 == 0 ? e : d) += std::clamp(s[4 * k + c], 0.0f, 1.0f);
            const double diff = e / even - d / odd;
            noise += diff * diff * scale;
        }
        measures[static_cast<size_t>(o)].noise += noise / 3.0;
    }
}

void addChange(const Image& image, const Image& base, std::span<const int32_t> owners,
               std::span<const size_t> objects, std::span<const float> scales,
               std::vector<FootprintMeasure>& measures) {
    std::vector<double> sums(measures.size(), 0.0);
    std::vector<uint8_t> measured(measures.size(), 0);
    for (size_t i : objects) measured[i] = 1;
    for (size_t p = 0; p < owners.size(); ++p) {
        const int32_t o = owners[p];
        if (o < 0 || !measured[static_cast<size_t>(o)]) continue;
        const float* a = &image.rgba[4 * p];
        const float* b = &base.rgba[4 * p];
        double d = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double e =
                static_cast<double>(std::clamp(a[c], 0.0f, 1.0f)) - std::clamp(b[c], 0.0f, 1.0f);
            d += e * e;
        }
        sums[static_cast<size_t>(o)] += d / 3.0;
    }
    for (size_t i : objects) {
        measures[i].scales.push_back(scales[i]);
        measures[i].change.push_back(sums[i]);
    }
}

bool changeAllowed(const FootprintMeasure& m, size_t k, const FootprintCalibrationOptions& o) {
    return k < m.change.size() &&
           m.change[k] <= o.tolerance * m.noise + o.floor * static_cast<double>(m.pixels);
}

float chosenFootprint(const FootprintMeasure& m, const FootprintCalibrationOptions& o) {
    float refused = std::numeric_limits<float>::infinity();
    for (size_t k = 0; k < m.scales.size(); ++k)
        if (!changeAllowed(m, k, o)) refused = std::min(refused, m.scales[k]);
    float scale = 1.0f;
    for (size_t k = 0; k < m.scales.size(); ++k)
        if (changeAllowed(m, k, o) && m.scales[k] < refused) scale = std::max(scale, m.scales[k]);
    return scale;
}

void keepCheckerboard(std::vector<int32_t>& owners, int width, int height, int tileSize,
                      int margin) {
    for (int y = 0; y < height; ++y) {
        const int ty = y / tileSize, y0 = ty * tileSize, y1 = std::min(height, y0 + tileSize);
        const bool insideY =
            (y0 == 0 || y - y0 >= margin) && (y1 == height || y1 - 1 - y >= margin);
        for (int x = 0; x < width; ++x) {
            const int tx = x / tileSize, x0 = tx * tileSize, x1 = std::min(width, x0 + tileSize);
            const bool inside =
                insideY && (x0 == 0 || x - x0 >= margin) && (x1 == width || x1 - 1 - x >= margin);
            if (!inside || (tx + ty) % 2 != 0) owners[static_cast<size_t>(y) * width + x] = -1;
        }
    }
}

std::vector<PixelRect> tilesOwnedBy(std::span<const int32_t> owners, int width, int height,
                                    std::span<const size_t> objects, int tileSize) {
    std::vector<uint8_t> wanted;
    for (size_t i : objects) {
        if (i >= wanted.size()) wanted.resize(i + 1, 0);
        wanted[i] = 1;
    }
    std::vector<PixelRect> tiles;
    for (int y0 = 0; y0 < height; y0 += tileSize)
        for (int x0 = 0; x0 < width; x0 += tileSize) {
            const int x1 = std::min(width, x0 + tileSize), y1 = std::min(height, y0 + tileSize);
            bool any = false;
            for (int y = y0; y < y1 && !any; ++y)
                for (int x = x0; x < x1 && !any; ++x) {
                    const int32_t o = owners[static_cast<size_t>(y) * width + x];
                    any = o >= 0 && static_cast<size_t>(o) < wanted.size() &&
                          wanted[static_cast<size_t>(o)];
                }
            if (any) tiles.push_back({x0, y0, x1, y1});
        }
    return tiles;
}

// The pipeline's step (multiphase_renderer.cpp lists it). The frame was shaded at every
// object's current footprint; the tiles of a checkerboard holding the objects measured are
// shaded again, each object at its candidate of a bisection, with the tiles that reads
// filled as at constant quality, so each change is the footprint's alone. The frame's own
// samples are put back after: it is the frame its pass shaded, and the frames after it are
// shaded at the footprints chosen (shading it again would cost a frame's shading for a
// first frame a few hundredths of a dB better).
void MultiphaseRenderer::calibrateFootprints(int frame,
                                             std::span<const ObjectRepresentation* const> drawn,
                                             FrameStats& stats) {
    const FootprintCalibrationOptions& o = options_.footprints;
    // A view that holds still replays its first frame's probed inputs in every later frame
    // (view_reuse.h): a wider footprint would save nothing after the first.
    const bool replays = !viewAnimated() && dynamicOptions_.reuseBytes > 0;
    if (!o.enabled || replays || o.scales.empty() || options_.frameBudgetSeconds > 0.0 ||
        planLast_ - frame < o.minFrames || dynamic_.abandoned() || !dynamic_.complete())
        return;
    // Most frames have no object left to measure that could own minPixels pixels (a point
    // shades at most a 2x2 quad's pixels) or that has grown since it last owned too few:
    // pixelOwners, whose window reads the whole visibility, had cost 2-3% of every steady
    // frame.
    const std::vector<ObjectFrameCost>& costs = dynamic_.objectCosts();
    std::vector<uint8_t> looked(slots_.size(), 0);
    bool any = false;
    for (size_t i = 0; i < slots_.size() && i < costs.size(); ++i) {
        const uint64_t points = costs[i].shadingPoints;
        looked[i] = drawn[i] && drawn[i]->map && !slots_[i].footprintMeasured &&
                    4 * points >= static_cast<uint64_t>(std::max(1, o.minPixels)) &&
                    points >= 2 * slots_[i].footprintTooFewAt;
        any = any || looked[i];
    }
    if (!any) return;
    const int width = frame_.width, height = frame_.height;
    std::vector<uint64_t> pixels;
    std::vector<int32_t> owners =
        pixelOwners(dynamic_.visibility(), slots_.size(), dynamic_.layout()->filterReach(), pixels);
    keepCheckerboard(owners, width, height, std::max(1, o.tileSize),
                     dynamic_.layout()->filterReach());
    pixels.assign(slots_.size(), 0);
    for (int32_t owner : owners)
        if (owner >= 0) ++pixels[static_cast<size_t>(owner)];
    std::vector<size_t> measured;
    for (size_t i = 0; i < slots_.size(); ++i) {
        if (!looked[i]) continue;
        if (pixels[i] >= static_cast<uint64_t>(std::max(1, o.minPixels)))
            measured.push_back(i);
        else
            slots_[i].footprintTooFewAt = std::max<uint64_t>(1, costs[i].shadingPoints);
    }
    if (measured.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    const ScopedSpan span(options_.trace, "footprint calibration", PhaseKind::Dynamic,
                          SpanLevel::Phase, -1, frame);
    const DynamicPhase::KeptSamples kept = dynamic_.keepSamples();
    std::vector<FootprintMeasure> measures(slots_.size());
    for (size_t i : measured) measures[i].pixels = pixels[i];
    addSampleNoise(dynamic_.samples(), dynamic_.uniformPixels(), owners, measures);
    Image base(width, height), image(width, height);
    dynamic_.resolveAgain(base, tilesOwnedBy(owners, width, height, measured, o.tileSize));
    std::vector<float> scales = dynamicOptions_.objectFootprint;
    scales.resize(slots_.size(), 1.0f);
    // Per object, the candidates known allowed up to `low` and refused from `high` on.
    const int candidates = static_cast<int>(o.scales.size());
    std::vector<int> low(slots_.size(), -1), high(slots_.size(), candidates);
    std::vector<size_t> searching = measured;
    TileFillResult fills;
    while (!searching.empty()) {
        for (size_t i : searching)
            scales[i] = o.scales[static_cast<size_t>((low[i] + high[i]) / 2)];
        const RefinePass pass{dynamicOptions_.shadingRate, dynamicOptions_.footprintScale,
                              std::chrono::steady_clock::time_point::max(), scales};
        const std::vector<PixelRect> tiles =
            tilesOwnedBy(owners, width, height, searching, o.tileSize);
        for (int attempt = 0;; ++attempt) {
            std::vector<TileRequest> missing;
            dynamic_.refine(tiles, pass, missing);
            if (missing.empty() || attempt >= 3) break;
            tiles_.fill(missing, drawn, fillLimits(CacheRoom::EvictAndExceed, frame), fills);
        }
        dynamic_.resolveAgain(image, tiles);
        addChange(image, base, owners, searching, scales, measures);
        std::erase_if(searching, [&](size_t i) {
            const int mid = (low[i] + high[i]) / 2;
            (changeAllowed(measures[i], measures[i].change.size() - 1, o) ? low[i] : high[i]) = mid;
            // Its neighbours' next passes see it at a scale known allowed.
            scales[i] = low[i] >= 0 ? o.scales[static_cast<size_t>(low[i])] : 1.0f;
            return high[i] - low[i] <= 1;
        });
    }
    dynamic_.restoreSamples(kept);
    countFills(fills, stats);
    for (size_t i : measured) {
        ObjectSlot& slot = slots_[i];
        slot.footprintMeasured = true;
        slot.footprintScale = chosenFootprint(measures[i], o);
        slot.report.footprint = measures[i];
        slot.report.footprintScale = slot.footprintScale;
    }
    dynamicOptions_.objectFootprint = footprintScales();
    stats.footprintCalibration.objects += measured.size();
    stats.footprintCalibration.seconds += secondsSince(start);
}

std::vector<float> MultiphaseRenderer::footprintScales() const {
    std::vector<float> scales(slots_.size(), 1.0f);
    bool any = false;
    for (size_t i = 0; i < slots_.size(); ++i) {
        scales[i] = slots_[i].footprintScale;
        any = any || scales[i] != 1.0f;
    }
    if (!any) scales.clear();
    return scales;
}

}  // namespace mpshade
