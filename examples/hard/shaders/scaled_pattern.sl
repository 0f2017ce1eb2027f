// scaled_pattern.sl -- a pattern whose frequency is a parameter, so the same scene at
// another scale shades alike when the frequency is divided by the scale.
surface scaled_pattern(
    color a      = color(0.8, 0.3, 0.2),
    color b      = color(0.2, 0.5, 0.8),
    float freq   = 3.0,
    float Ks     = 0.4,
    float roughness = 0.3)
{
    float n = fbm(P * freq, 5);
    color Cd = mix(a, b, smoothstep(-0.3, 0.3, n));
    Ci = Cd * (ambient() + diffuse(N)) + Ks * specular(N, -I, roughness);
}
