#include "controller/representation_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "shadermaps/chart_aspect.h"

namespace mpshade {

double footprintElongation(const Surface& surface, const ObjectState& state,
                           const CameraState& camera, float levelAnisotropy) {
    const int charts = chartCount(surface);
    const int stride = std::max(1, charts / 64);
    const int grid = charts == 1 ? 16 : (charts < 16 ? 4 : 2);
    const double cap = std::max(1.0f, levelAnisotropy > 0.0f ? levelAnisotropy : 1e30f);
    double pixels = 0.0, sum = 0.0;
    for (int chart = 0; chart < charts; chart += stride)
        for (int j = 0; j < grid; ++j)
            for (int i = 0; i < grid; ++i) {
                const float u = (static_cast<float>(i) + 0.5f) / static_cast<float>(grid);
                const float v = (static_cast<float>(j) + 0.5f) / static_cast<float>(grid);
                const SurfaceSample p = evaluate(surface, {chart, u, v});
                const glm::vec3 world = glm::vec3(state.objectToWorld * glm::vec4(p.P, 1.0f));
                float x = 0.0f, y = 0.0f;
                if (!camera.project(world, x, y) || !(x >= 0.0f && y >= 0.0f) ||
                    !(x < static_cast<float>(camera.width) &&
                      y < static_cast<float>(camera.height)))
                    continue;
                const glm::vec3 toP = p.P - state.eye;
                const double distance2 = glm::dot(toP, toP);
                const double normal = glm::length(p.N);
                const double area = glm::length(glm::cross(p.dPdu, p.dPdv));
                const double cosine =
                    std::fabs(glm::dot(toP, p.N)) / std::sqrt(distance2 * normal * normal);
                if (!(cosine > 0.0 && area > 0.0 && std::isfinite(area * cosine / distance2)))
                    continue;
                const double w = area * cosine / distance2;
                sum += w * std::min(1.0 / cosine, cap);
                pixels += w;
            }
    return pixels > 0.0 ? sum / pixels : 1.0;
}

RepresentationPlanner::RepresentationPlanner(const Scene& scene, const StaticPhase& statics,
                                             const RepresentationCostModel& model,
                                             std::optional<Representation> forced)
    : scene_(scene),
      statics_(statics),
      model_(model),
      forced_(forced),
      framesSeen_(scene.objects.size()) {}

void RepresentationPlanner::plan(int first, int last, int width, int height) {
    first_ = first;
    width_ = width;
    height_ = height;
    for (std::vector<int>& seen : framesSeen_)
        seen.assign(static_cast<size_t>(std::max(0, last - first)), 0);
    for (int f = first; f < last; ++f) {
        const float t = scene_.frameTime(f);
        const CameraState camera = cameraAt(scene_, t, width_, height_);
        const size_t k = static_cast<size_t>(f - first);
        for (size_t i = 0; i < scene_.objects.size(); ++i) {
            const bool seen = objectInView(*scene_.objects[i].surface,
                                           objectAt(scene_.objects[i], t, camera), camera);
            framesSeen_[i][k] = (k > 0 ? framesSeen_[i][k - 1] : 0) + (seen ? 1 : 0);
        }
    }
}

ObjectCostInputs RepresentationPlanner::costInputs(size_t i, const ObjectSlot& slot, int frame,
                                                   const ObjectState& state,
                                                   const CameraState& camera, int spp,
                                                   const DynamicOptions& dynamic) const {
    const SceneObject& obj = scene_.objects[i];
    const ObjectShading& shading = statics_.shading(i);
    const ShaderMapOptions& mapOptions = statics_.options().shaderMap;
    const int tile = mapOptions.tileSize + 2 * mapOptions.border;
    ObjectCostInputs in;
    in.charts = chartCount(*obj.surface);
    // The map's always-resident levels: at 16-texel tiles the 32 x 32 level is four tiles
    // and the five below one each, fewer where a chart's texels are fewer along an axis
    // (chart_aspect.h).
    const ShaderMapOptions map = statics_.mapOptions(i);
    const ChartShifts shifts = chartShifts(
        *obj.surface, map.chartAspect ? chartShiftRoom(map.resolution, map.tileSize) : 0);
    in.pinnedTiles =
        coarseLevelTiles(shifts, map.resolution, map.tileSize, map.alwaysResidentLevels);
    in.pinnedBytes = in.pinnedTiles * tile * tile *
                     static_cast<double>(shading.factored.staticPart.channelOutputs.size()) *
                     (map.halfPrecision ? 2.0 : 4.0);
    in.haveMap = slot.representation && slot.representation->map;
    in.pinnedUpFront = mapOptions.fillPinnedUpFront;
    // The screen area: the object's bounding sphere, projected, within the screen.
    const Bounds3 b = surfaceBounds(*obj.surface);
    const float ppu = 0.5f * static_cast<float>(camera.height) / camera.tanHalfFovY;
    const float distance = std::max(glm::length(state.eye - b.center()), 1e-20f);
    const float radius = 0.5f * b.diagonal();
    const double projected =
        distance > radius ? 3.14159265 * std::pow(ppu * radius / distance, 2.0) : 1e30;
    in.coveredPixels = std::min(static_cast<double>(camera.width) * camera.height, projected);
    in.frames = std::max(1, framesSeenFrom(i, frame));
    in.elongation = footprintElongation(*obj.surface, state, camera, dynamic.probe.levelAnisotropy);
    in.combinedRuns = predictedCombinedRuns(i, frame, state);
    in.screenPixels = static_cast<double>(camera.width) * camera.height;
    in.channels = static_cast<int>(shading.factored.staticPart.channelOutputs.size());
    in.staticCostUnits = shading.factored.staticCost;
    in.recomputedCostUnits = shading.factored.recomputedStaticCost;
    in.originalCostUnits = shading.factored.originalCost;
    in.samplesPerPixel = spp;
    in.shadingRate = dynamic.shadingRate;
    in.footprintScale = dynamic.footprintScale;
    return in;
}

Representation RepresentationPlanner::choose(size_t i, ObjectSlot& slot, int frame,
                                             const ObjectState& state, const CameraState& camera,
                                             int spp, const DynamicOptions& dynamic,
                                             ObjectCostInputs& in) const {
    const Representation asked = forced_.value_or(scene_.objects[i].representation);
    in = costInputs(i, slot, frame, state, camera, spp, dynamic);
    if (slot.goesDirect && asked == Representation::Auto) {
        char text[320];
        std::snprintf(text, sizeof text,
                      "auto: direct; its stored representation's work, frames running, cost "
                      "%.1f ms of CPU a frame where the reference would spend %.1f ms on it "
                      "(the cost model's figures for the tiles filled and points shaded)",
                      slot.measuredMs, slot.referenceMs);
        slot.report.reason = text;
        return Representation::Direct;
    }
    if (asked == Representation::Direct && !statics_.shading(i).directAllowed) {
        slot.report.reason =
            "the scene asks for direct, but its shader traces occlusion rays from the shading "
            "point, which facets at the geometric tolerance would start inside the surface: "
            "auto instead";
        in.combinedFacets = statics_.combinedFacets(i, state, camera);
        const RepresentationChoice choice = chooseRepresentation(in, model_);
        slot.report.reason += " (" + choice.reason + ")";
        return choice.kind;
    }
    if (asked == Representation::Facets)
        in.combinedFacets = statics_.combinedFacets(i, state, camera);
    if (asked != Representation::Auto) {
        slot.report.reason = forced_ ? "forced by the renderer's options" : "the scene asks for it";
        std::string tooBig;
        if (asked == Representation::ShaderMap && !in.haveMap &&
            !shaderMapFits(in, tooBig, model_)) {
            slot.report.reason += ", but " + tooBig + ": facets instead";
            return Representation::Facets;
        }
        return asked;
    }
    in.combinedFacets = statics_.combinedFacets(i, state, camera);
    const RepresentationChoice choice = chooseRepresentation(in, model_);
    slot.report.reason = choice.reason;
    return choice.kind;
}

bool RepresentationPlanner::singlePhasePays(std::span<const size_t> due,
                                            std::span<const ObjectCostInputs> dueInputs,
                                            std::span<const uint8_t> visible,
                                            std::span<const ObjectSlot> slots,
                                            const FrameState& frame, int index,
                                            const DynamicOptions& dynamic, bool leastCost) const {
    int served = 1;
    for (const ObjectCostInputs& in : dueInputs) served = std::max(served, in.frames);
    double multi = 0.0, single = 0.0;
    std::vector<int> dueAt(visible.size(), -1);
    for (size_t k = 0; k < due.size(); ++k) dueAt[due[k]] = static_cast<int>(k);
    for (size_t i = 0; i < visible.size(); ++i) {
        if (!visible[i]) continue;
        const int k = dueAt[i];
        const ObjectSlot& slot = slots[i];
        ObjectCostInputs in =
            k >= 0 ? dueInputs[static_cast<size_t>(k)]
                   : costInputs(i, slot, index, frame.objects[i], frame.camera, frame.spp, dynamic);
        if (k < 0)
            in.combinedFacets = static_cast<double>(slot.representation->mesh.facetCount());
        else if (leastCost)
            // Unsurveyed: facets at a quarter of the 20-50 per covered pixel the survey
            // usually finds.
            in.combinedFacets = 5.0 * in.coveredPixels;
        const RepresentationChoice c = chooseRepresentation(in, model_);
        const double frames = std::min(served, std::max(1, in.frames));
        const double facets =
            (k >= 0 ? c.facetsStaticSeconds : 0.0) + frames * c.facetsFrameSeconds;
        const double map = (k >= 0 ? c.mapStaticSeconds : 0.0) + frames * c.mapFrameSeconds;
        const double direct = frames * c.directFrameSeconds;
        const Representation kind = k >= 0 ? slot.kind : slot.representation->kind;
        if (k >= 0 && leastCost)
            multi += std::min(facets, map);  // whichever stored representation is cheaper
        else
            multi += kind == Representation::Facets   ? facets
                     : kind == Representation::Direct ? direct
                                                      : map;
        single += frames * c.singlePhaseFrameSeconds;
    }
    return single < multi;
}

int RepresentationPlanner::predictedCombinedRuns(size_t object, int frame,
                                                 const ObjectState& state) const {
    // Facets diced for the view at P/2 are diced again when the eye comes closer (their
    // projected edges grow) or leaves the range: count those events along the planned
    // frames that see the object.
    const std::vector<int>& seen = framesSeen_[object];
    if (seen.empty()) return 1;
    const SceneObject& obj = scene_.objects[object];
    const Bounds3 b = surfaceBounds(*obj.surface);
    const glm::vec3 center = b.center();
    const float radius = 0.5f * b.diagonal();
    auto distance = [&](const glm::vec3& eye) {
        return std::max(glm::length(eye - center) - radius, 1e-3f * radius);
    };
    float diced = distance(state.eye);
    glm::vec3 direction = glm::normalize(state.eye - center);
    int runs = 1;
    const int last = first_ + static_cast<int>(seen.size());
    for (int f = std::max(frame + 1, first_); f < last; ++f) {
        const size_t k = static_cast<size_t>(f - first_);
        if (seen[k] == (k > 0 ? seen[k - 1] : 0)) continue;  // not seen in frame f
        const float t = scene_.frameTime(f);
        const CameraState camera = cameraAt(scene_, t, width_, height_);
        const glm::vec3 eye = objectAt(obj, t, camera).eye;
        const float d = distance(eye);
        const glm::vec3 dir = glm::normalize(eye - center);
        if (d < 0.95f * diced || d > obj.range.distanceFactor * diced ||
            glm::dot(dir, direction) < std::cos(glm::radians(obj.range.angle))) {
            ++runs;
            diced = d;
            direction = dir;
        }
    }
    return runs;
}

int RepresentationPlanner::framesSeenFrom(size_t object, int frame) const {
    const std::vector<int>& seen = framesSeen_[object];
    if (seen.empty()) return scene_.frameCount() - frame;  // no plan: assume every frame
    const int first = std::clamp(frame - first_, 0, static_cast<int>(seen.size()) - 1);
    return seen.back() - (first > 0 ? seen[static_cast<size_t>(first) - 1] : 0);
}

}  // namespace mpshade
