// chart_aspect.h -- how much longer a chart's texels are along one of its axes than the
// other, so that a shader map's texels are about as long as they are wide on the surface.
//
// A map level is a grid over a chart's [0,1]^2. Where the chart's parameterization is
// stretched -- a torus's u runs around the ring, R / r times as long as v around the tube;
// a column's faces are tall and thin -- square grids make texels that are long on the
// surface along one axis and short along the other. A probe picks its level by the
// footprint's shorter axis in texels, so such a chart is filled at the short texels'
// density along both axes: on the examples' walls, columns, tori and teapot patches 2.7-5.2
// times the texels an isotropic grid needs (area-weighted over each object's charts), and
// their probes' footprints are as elongated, which takes two Feline taps where one would
// do. So each chart gets a shift per axis: at level L its u axis has R >> (L + shiftU)
// texels and its v axis R >> (L + shiftV), at least one (at most one shift is nonzero).
//
// The shift is the area-weighted mean of log2(|dP/du| / |dP/dv|) over a 4 x 4 grid of the
// chart, rounded down, capped at kMaxChartShift: an axis loses half its texels only where
// it is at least twice as long. Rounded to nearest, a chart stretched 1.5-2x (a sphere, 2
// cos(latitude) times as long along its longitude, most of its area at 1.5x) was stretched
// the other way instead and read a finer level: the vase at 240x135 filled 15% more of its
// tiles (4.4-4.6x against 5.1-5.3x rounded down) and the courtyard there lost 0.6 dB more.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/surface.h"

namespace mpshade {

constexpr int kMaxChartShift = 4;  // 16:1
// Charts beyond this many keep square grids: 16 evaluations a chart would otherwise cost a
// large point cloud seconds, and its discs (polar charts, alike) are drawn as facets anyway.
constexpr int kMaxAspectCharts = 1 << 14;

struct ChartShifts {
    std::vector<uint8_t> u, v;  // per chart, each in [0, kMaxChartShift], one of them 0
};

// The largest shift a map of `resolution` texels a side in tiles of `tileSize` allows: each
// axis keeps at least a tile's texels at level 0.
inline int chartShiftRoom(int resolution, int tileSize) {
    int room = 0;
    while (room < kMaxChartShift && (resolution >> (room + 1)) >= tileSize) ++room;
    return room;
}

// The shifts of every chart of `surface`, each at most `maxShift` (a map of resolution R
// passes at most log2(R): an axis keeps at least one texel at level 0). All zero for a
// surface of more than kMaxAspectCharts charts.
ChartShifts chartShifts(const Surface& surface, int maxShift = kMaxChartShift);

// Tiles of the coarsest `levels` levels of every chart with these shifts, in a map of
// `resolution` texels a side (a power of two) cut into tiles of `tileSize`.
double coarseLevelTiles(const ChartShifts& shifts, int resolution, int tileSize, int levels);

}  // namespace mpshade
