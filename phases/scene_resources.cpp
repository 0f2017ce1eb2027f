#include "phases/scene_resources.h"

#include "scene/variability.h"
#include "shading/shader_compiler.h"

namespace mpshade {

SceneResources::SceneResources(const Scene& scene, RayScenes rayScenes) : scene_(scene) {
    for (const SceneObject& obj : scene.objects) {
        ObjectResources r;
        r.kernel =
            forObject(scene, obj, [&] { return buildKernel(*obj.shader, bindingOf(scene, obj)); });
        bool casts = rayScenes == RayScenes::All;
        for (const Inst& inst : r.kernel->program().insts)
            casts = casts || inst.op == Op::Occlusion;
        if (casts) {
            auto& rs = rayScenes_[obj.surface.get()];
            if (!rs) rs = std::make_unique<SurfaceRayScene>(*obj.surface);
            r.rayScene = rs.get();
        }
        r.occlusionBias = 1e-4f * std::max(surfaceBounds(*obj.surface).diagonal(), 1e-6f);
        objects_.push_back(std::move(r));
    }
}

FrameState frameStateAt(const SceneResources& resources, int frame, int width, int height,
                        int spp) {
    const Scene& scene = resources.scene();
    FrameState f;
    f.index = frame;
    f.width = width > 0 ? width : scene.settings.width;
    f.height = height > 0 ? height : scene.settings.height;
    f.spp = spp > 0 ? spp : scene.settings.samplesPerPixel;
    f.time = scene.frameTime(frame);
    f.camera = cameraAt(scene, f.time, f.width, f.height);
    const size_t n = scene.objects.size();
    f.objects.resize(n);
    f.params.resize(n);
    f.lights.resize(n);
    f.uniforms.resize(n);
    for (size_t i = 0; i < n; ++i) {
        const SceneObject& obj = scene.objects[i];
        const ObjectResources& res = resources.object(i);
        f.objects[i] = objectAt(obj, f.time, f.camera);
        // Every specialization of one binding has the same animated-parameter slots.
        animatedParamsAt(obj, res.kernel->program(), f.time, f.params[i]);
        lightsAt(scene, f.objects[i], f.time, f.lights[i]);
        ShadingUniforms& u = f.uniforms[i];
        u.time = f.time;
        u.eye = f.objects[i].eye;
        u.params = f.params[i];
        u.lights = f.lights[i];
        u.occluder = res.rayScene;
        u.occlusionBias = res.occlusionBias;
    }
    return f;
}

WorldRayScene::WorldRayScene(const SceneResources& resources,
                             const std::vector<ObjectState>& states) {
    RTCDevice device = embreeDevice();
    scene_ = rtcNewScene(device);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    for (size_t i = 0; i < resources.objectCount(); ++i) {
        RTCGeometry inst = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(inst, resources.object(i).rayScene->scene());
        rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR,
                                &states[i].objectToWorld[0][0]);
        rtcCommitGeometry(inst);
        rtcAttachGeometryByID(scene_, inst, static_cast<unsigned>(i));
        rtcReleaseGeometry(inst);
    }
    rtcCommitScene(scene_);
}

WorldRayScene::~WorldRayScene() {
    rtcReleaseScene(scene_);
}

}  // namespace mpshade
