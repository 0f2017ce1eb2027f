// wood.sl -- concentric growth rings around the y axis, bent by noise, with a sheen.
surface wood(
    color light     = color(0.72, 0.50, 0.30),
    color dark      = color(0.38, 0.22, 0.11),
    float ringScale = 6.0,
    float grain     = 0.35,
    float Ks        = 0.15,
    float roughness = 0.35)
{
    point Q = P * 0.35;
    float r = sqrt(Q[0] * Q[0] + Q[2] * Q[2]) * ringScale;
    r += grain * fbm(Q * 4.0, 4);
    float ring = smoothstep(0.0, 0.8, fract(r)) - smoothstep(0.85, 1.0, fract(r));
    float fleck = 0.08 * snoise(point(Q[0] * 40.0, Q[1] * 2.0, Q[2] * 40.0));
    color Cd = mix(dark, light, clamp(ring + fleck, 0.0, 1.0));
    // Lighting on N, not faceforward(N, I): that would make even diffuse light depend on
    // the view, and the factoring could no longer bake it into the static part.
    Ci = Cd * (ambient() + diffuse(N)) + Ks * specular(N, -I, roughness);
}
