// map_demand.h -- how much of an object's shader map the scene's frames ask for, worked
// out before any frame is rendered, so `mpshade factor` can put a stored channel's cost in
// bytes at the map's real resolution (the issue an author meets otherwise only in a later
// render's map_bytes).
//
// The map is virtual (shader_map.h): level 0 is the object's resolution cap, and a frame
// fills only the tiles its probes read. A probe reads the level whose texel matches the
// footprint's minor axis, widened to major / levelAnisotropy (probe.h's ShrinkMajor cap;
// major / maxAnisotropy otherwise), and the level above it where the narrow level blend
// gives that weight. So over a grid of cells on each chart, at frames spread over the scene:
// the screen Jacobian of the chart coordinates gives the footprint in texels (each chart
// axis at its own resolution, chart_aspect.h), hence the level; points two a tile side
// within the cell give the tiles it reads there. A cell wider than a few pixels as seen
// from the eye is split in four until it is not (a floor seen at a grazing angle from close
// by). Cells outside the image, behind the near plane, facing away on a closed surface or
// hidden behind another surface (a ray from the eye, through the frame's world) ask for
// nothing; a transparent surface in front counts as hiding. The always-resident coarse
// levels (nine tiles a chart, fewer where its texels are fewer along an axis), which `play`
// fills up front and `render` only where asked, are counted apart. Checked against the
// tiles a render of that frame fills (tests/phases).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "phases/dynamic_phase.h"
#include "phases/scene_resources.h"

namespace mpshade {

struct MapDemandOptions {
    int points = 4096;  // cells over the charts, at most (at least one a chart)
    int frames = 8;     // frames spread over the scene, first and last included
    int firstFrame = 0,
        lastFrame = -1;           // the frames to spread over, [first, last); -1: the scene's
    int width = 0, height = 0;    // the image; 0: the scene's
    int samplesPerPixel = 0;      // 0: the scene's
    float footprintScale = 1.0f;  // DynamicOptions::footprintScale
    ProbeOptions probe = DynamicOptions{}.probe;  // the level it reads (cap, levelAnisotropy)
    int tileSize = 16;                            // texels a tile side (ShaderMapOptions)
    int border = 1;                               // texels around each tile
    bool chartAspect = true;                      // ShaderMapOptions::chartAspect
};

struct MapDemand {
    int resolution = 0;          // level-0 texels a chart side (the object's cap, a power of two)
    int frame = -1;              // the frame that asks most; -1: no frame sees the object
    double coveredPixels = 0.0;  // the object's visible screen area at that frame
    double tiles = 0.0;          // tiles that frame asks for
    double pinnedTiles = 0.0;    // the always-resident levels' (play fills them up front)
    int finestLevel = 0;         // the finest level any cell asks for at that frame
    int tileTexels = 0;          // texels a tile holds, its border included
    // Every frame looked at, in order, and the tiles each asks for (0 where it does not see
    // the object): the same frames for every object of one estimate.
    std::vector<int> frames;
    std::vector<double> frameTiles;

    // Bytes of `count` tiles for an n-tuple of `channels` floats, 4 or 2 bytes each.
    double bytes(double count, int channels, bool half) const {
        return count * tileTexels * channels * (half ? 2.0 : 4.0);
    }
    double bytes(int channels, bool half) const { return bytes(tiles, channels, half); }
};

// One estimate per object of `objects`. `resources` must have ray scenes of every surface
// (SceneResources::RayScenes::All): they hide what lies behind.
std::vector<MapDemand> estimateMapDemands(const SceneResources& resources,
                                          std::span<const size_t> objects,
                                          const MapDemandOptions& options = {});

}  // namespace mpshade
