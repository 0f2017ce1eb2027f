#include "app/profile_command.h"

#include <cstdio>
#include <filesystem>

#include <unistd.h>

#include "app/frame_request.h"
#include "app/output_files.h"
#include "controller/cost_profile.h"
#include "geometry/error.h"
#include "scene/scene.h"

namespace mpshade {

int runProfileCommand(const ProfileCommandOptions& options) {
    const FrameRequest request =
        loadFrameRequest({options.scene, options.frames, options.size, options.spp, options.seed});
    const Scene& scene = request.scene;
    ProfileOptions po;
    po.render = request.render;
    po.first = request.first;
    po.last = request.last;
    const std::shared_ptr<TileStore> store = openStore(options.run);
    po.multiphase.staticPhase.store = store;
    prepareOutputFolder(options.outDir);

    std::vector<std::string> names;
    for (const SceneObject& o : scene.objects) names.push_back(o.name);
    TraceRecorder trace(names);
    const bool tty = !options.quiet && isatty(STDERR_FILENO);
    const CostProfile profile = profileScene(scene, options.scene, po, trace, [&](int frame) {
        if (tty)
            std::fprintf(stderr, "\rprofiling frame %d (%d of %d)", frame, frame - po.first + 1,
                         po.last - po.first);
    });
    if (tty) std::fprintf(stderr, "\n");
    const std::filesystem::path dir(options.outDir);
    writeTextFile(dir / "profile.md", profileMarkdown(profile));
    writeTextFile(dir / "trace.json", trace.chromeTraceJson());
    cleanUpStore(store, options.run, scene);
    if (!options.quiet) {
        double staticSeconds = 0.0, wall = 0.0;
        for (const FrameStats& s : profile.frames) {
            staticSeconds += s.staticWork.seconds;
            wall += s.wallSeconds;
        }
        std::fprintf(stderr,
                     "mpshade: %d frame(s) in %.2f s, %.0f%% of it static work; wrote %s "
                     "and %s (open it in https://ui.perfetto.dev)\n",
                     po.last - po.first, wall, wall > 0 ? 100.0 * staticSeconds / wall : 0.0,
                     (dir / "profile.md").string().c_str(), (dir / "trace.json").string().c_str());
    }
    return 0;
}

}  // namespace mpshade
