#include "phases/scene_resources.h"

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "geometry/error.h"
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

void SceneResources::buildRayScenes() const {
    std::vector<const SurfaceRayScene*> scenes;
    for (const auto& [surface, rs] : rayScenes_) scenes.push_back(rs.get());
    tbb::parallel_for(size_t{0}, scenes.size(), [&](size_t k) { scenes[k]->triangleCount(); });
}

bool objectInView(const Surface& surface, const ObjectState& state, const CameraState& camera) {
    const Bounds3 b = surfaceBounds(surface);
    const glm::vec3 c = glm::vec3(state.objectToWorld * glm::vec4(b.center(), 1.0f)) - camera.eye;
    const float r = 0.5f * b.diagonal() * state.scale;
    const float depth = glm::dot(c, camera.forward);
    if (depth < camera.zNear - r || depth > camera.zFar + r) return false;
    const float tx = camera.tanHalfFovY * camera.aspect, ty = camera.tanHalfFovY;
    const glm::vec3 planes[4] = {glm::normalize(camera.right - tx * camera.forward),
                                 glm::normalize(-camera.right - tx * camera.forward),
                                 glm::normalize(camera.up - ty * camera.forward),
                                 glm::normalize(-camera.up - ty * camera.forward)};
    for (const glm::vec3& n : planes)
        if (glm::dot(c, n) > r) return false;
    return true;
}

FrameState frameStateAt(const SceneResources& resources, int frame, int width, int height,
                        int spp) {
    const Scene& scene = resources.scene();
    FrameState f;
    f.index = frame;
    MPSHADE_CHECK(width > 0 && height > 0 && spp > 0);
    f.width = width;
    f.height = height;
    f.spp = spp;
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
