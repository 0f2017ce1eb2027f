// plastic.sl -- a diffuse base under a GGX highlight; the highlight moves with the eye.
surface plastic(
    color Cs        = color(0.8, 0.1, 0.1),
    float Kd        = 0.8,
    float Ks        = 0.6,
    float roughness = 0.25)
{
    normal Nf = faceforward(N, I);
    Ci = Cs * (ambient() + Kd * diffuse(Nf)) + Ks * specular(Nf, -I, roughness);
}
