// marble.sl -- veined marble with baked self-occlusion and a moving GGX highlight.
surface marble(
    color base      = color(0.92, 0.90, 0.86),
    color vein      = color(0.18, 0.20, 0.35),
    float scale     = 3.0,
    float roughness = 0.25,
    float Ks        = 0.5,
    int   aoRays    = 16)
{
    float n  = fbm(P * scale, 6);
    // Thin veins where the bent sine crosses zero.
    float m  = 1.0 - smoothstep(0.0, 0.3, abs(sin(P[0] * scale + 4.0 * n)));
    color Cd = mix(base, vein, m);
    float ao = occlusion(P, N, aoRays);
    // Lighting on N, not faceforward(N, I): that would make even diffuse light depend on
    // the view, and the factoring could no longer bake it into the static part.
    Ci = Cd * (ambient() * ao + diffuse(N)) + Ks * specular(N, -I, roughness);
    Oi = 1.0;
}
