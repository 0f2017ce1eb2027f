#include "app/profile_command.h"

#include <cstdio>
#include <filesystem>

#include <unistd.h>

#include "app/command_line.h"
#include "app/memory_limit.h"
#include "app/output_files.h"
#include "controller/cost_profile.h"
#include "geometry/error.h"
#include "scene/scene.h"

namespace mpshade {

int runProfileCommand(const ProfileCommandOptions& options) {
    try {
        if (options.spp != -1 && (options.spp < 1 || options.spp > 1024))
            throw InputError({"--spp", 0, 0, {}},
                             "expected 1..1024, found " + std::to_string(options.spp));
        const Scene scene = loadScene(options.scene);
        ProfileOptions po;
        po.render.seed = options.seed;
        po.render.samplesPerPixel = options.spp > 0 ? options.spp : 0;
        parseImageSize(options.size, po.render.width, po.render.height);
        parseFrameRange(options.frames, scene.frameCount(), po.first, po.last);
        const int width = po.render.width > 0 ? po.render.width : scene.settings.width;
        const int height = po.render.height > 0 ? po.render.height : scene.settings.height;
        const int spp = options.spp > 0 ? options.spp : scene.settings.samplesPerPixel;
        FrameMemoryEstimate estimate = estimateFrameMemory(width, height, spp, true, false, -1);
        estimate.bytes += estimateRaySceneBytes(scene, false);
        checkMemory(estimate, defaultMemoryLimitBytes(),
                    !options.size.empty() || options.spp > 0 ? "--size/--spp"
                                                             : options.scene + ": settings");
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
        if (!options.quiet) {
            double staticSeconds = 0.0, wall = 0.0;
            for (const FrameStats& s : profile.frames) {
                staticSeconds += s.staticSeconds;
                wall += s.wallSeconds;
            }
            std::fprintf(stderr,
                         "mpshade: %d frame(s) in %.2f s, %.0f%% of it static work; wrote %s "
                         "and %s (open it in https://ui.perfetto.dev)\n",
                         po.last - po.first, wall, wall > 0 ? 100.0 * staticSeconds / wall : 0.0,
                         (dir / "profile.md").string().c_str(),
                         (dir / "trace.json").string().c_str());
        }
        return 0;
    } catch (const InputError& e) {
        std::fprintf(stderr, "mpshade: %s\n", e.what());
        return 2;
    } catch (const OutputError& e) {
        std::fprintf(stderr, "mpshade: error: %s\n", e.what());
        return 1;
    }
}

}  // namespace mpshade
