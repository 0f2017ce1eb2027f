#include "phases/map_precision.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include <glm/geometric.hpp>

#include "phases/split_verification.h"
#include "phases/static_phase.h"
#include "shadermaps/half_float.h"
#include "shadermaps/tile_store.h"
#include "shading/shading_batch.h"

namespace mpshade {
namespace {

std::string describe(const MapPrecisionCheck& c, const MapPrecisionOptions& o) {
    char text[200];
    if (c.largestValue > o.maxValue)
        std::snprintf(text, sizeof text, "float: a channel reaches %.3g, past %.3g", c.largestValue,
                      o.maxValue);
    else if (!(c.largestChange <= o.tolerance))
        std::snprintf(text, sizeof text,
                      "float: rounding the channels to binary16 moved an output by %.3g, "
                      "past %.3g",
                      c.largestChange, o.tolerance);
    else
        std::snprintf(text, sizeof text,
                      "half: rounding the channels to binary16 moved the outputs by at most %.3g "
                      "(%d points)",
                      c.largestChange, c.points);
    return text;
}

}  // namespace

MapPrecisionCheck checkHalfPrecision(const StaticPhase& statics, const Surface& surface,
                                     size_t object, const ShadingUniforms& uniforms,
                                     const MapPrecisionOptions& options) {
    MapPrecisionCheck check;
    const ObjectShading& obj = statics.shading(object);
    const size_t channels = obj.factored.staticPart.channelOutputs.size();
    if (channels == 0) {
        check.reason = "float: no channels";
        return check;
    }
    const std::vector<ChartPoint> at = spreadChartPoints(surface, options.points);
    const size_t n = at.size();
    check.points = static_cast<int>(n);
    ShadingBatch batch;
    batch.resize(n, channels);
    for (size_t i = 0; i < n; ++i) {
        const SurfaceSample g = evaluate(surface, at[i]);
        const glm::vec3 d = g.P - uniforms.eye;
        const float len = glm::length(d);
        batch.setPoint(i, g, at[i], len > 0.0f ? d / len : glm::vec3(0, 0, 1));
    }
    std::vector<float> workspace, outputs(6 * n);
    ShadingCounters counters;
    obj.staticKernel->run(uniforms, batch.in, n, batch.out, workspace, counters);
    obj.dynamicKernel->run(uniforms, batch.in, n, batch.out, workspace, counters);
    for (int k = 0; k < 3; ++k) {
        std::copy_n(batch.out.Ci[k], n, &outputs[static_cast<size_t>(k) * n]);
        std::copy_n(batch.out.Oi[k], n, &outputs[static_cast<size_t>(3 + k) * n]);
    }
    for (size_t c = 0; c < channels; ++c) {
        float* values = batch.channel(c);
        for (size_t i = 0; i < n; ++i) {
            if (std::isfinite(values[i]))
                check.largestValue = std::max(check.largestValue, std::fabs(double(values[i])));
            values[i] = halfToFloat(floatToHalf(values[i]));
        }
    }
    obj.dynamicKernel->run(uniforms, batch.in, n, batch.out, workspace, counters);
    for (int k = 0; k < 3; ++k)
        for (size_t i = 0; i < n; ++i) {
            check.largestChange =
                std::max({check.largestChange,
                          relativeOutputDifference(outputs[static_cast<size_t>(k) * n + i],
                                                   batch.out.Ci[k][i]),
                          relativeOutputDifference(outputs[static_cast<size_t>(3 + k) * n + i],
                                                   batch.out.Oi[k][i])});
        }
    check.half = check.largestValue <= options.maxValue && check.largestChange <= options.tolerance;
    check.reason = describe(check, options);
    return check;
}

MapPrecisionCheck checkHalfPrecisionKept(const StaticPhase& statics, const Surface& surface,
                                         size_t object, const ShadingUniforms& uniforms,
                                         const MapPrecisionOptions& options, TileStore* store,
                                         const Digest128& key) {
    // The record: the verdict, the largest value and change, the points.
    constexpr size_t kBytes = 1 + 2 * sizeof(double) + sizeof(int32_t);
    MapPrecisionCheck check;
    std::vector<unsigned char> record;
    if (store && store->readRecord(key, record) && record.size() == kBytes) {
        check.half = record[0] != 0;
        std::memcpy(&check.largestValue, &record[1], sizeof(double));
        std::memcpy(&check.largestChange, &record[1 + sizeof(double)], sizeof(double));
        std::memcpy(&check.points, &record[1 + 2 * sizeof(double)], sizeof(int32_t));
        check.reason =
            (check.half ? "half" : "float") + std::string(" (checked before: in the store)");
        return check;
    }
    check = checkHalfPrecision(statics, surface, object, uniforms, options);
    if (store) {
        record.assign(kBytes, 0);
        record[0] = check.half ? 1 : 0;
        std::memcpy(&record[1], &check.largestValue, sizeof(double));
        std::memcpy(&record[1 + sizeof(double)], &check.largestChange, sizeof(double));
        std::memcpy(&record[1 + 2 * sizeof(double)], &check.points, sizeof(int32_t));
        store->writeRecord(key, record);
    }
    return check;
}

}  // namespace mpshade
