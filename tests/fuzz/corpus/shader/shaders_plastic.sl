// plastic.sl -- a diffuse base under a GGX highlight; the highlight moves with the eye.
surface plastic(
    color Cs        = color(0.8, 0.1, 0.1),
    float Kd        = 0.8,
    float Ks        = 0.6,
    float roughness = 0.25)
{
    // Lighting on N, not faceforward(N, I): that would make even diffuse light depend on
    // the view, and the factoring could no longer bake it into the static part.
    Ci = Cs * (ambient() + Kd * diffuse(N)) + Ks * specular(N, -I, roughness);
}
