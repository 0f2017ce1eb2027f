// Loads a scene, renders one small frame multi-phase and prints its size and coverage: the
// installed headers, libraries and dependencies are enough to build and run this.
#include <cstdio>

#include "controller/multiphase_renderer.h"
#include "scene/scene.h"

int main(int argc, char** argv) {
    if (argc != 2) return 2;
    const mpshade::Scene scene = mpshade::loadScene(argv[1]);
    mpshade::MultiphaseRenderer renderer(scene);
    mpshade::RenderOptions options;
    options.width = 32;
    options.height = 18;
    mpshade::FrameStats stats;
    const mpshade::Image image = renderer.renderFrame(0, options, stats);
    double covered = 0.0;
    for (size_t i = 3; i < image.rgba.size(); i += 4) covered += image.rgba[i];
    std::printf("%dx%d covered %.0f\n", image.width, image.height, covered);
    return covered > 0.0 ? 0 : 1;
}
