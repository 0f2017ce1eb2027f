// fine_noise.sl -- noise far finer than a pixel at the view's distance: point samples alias
// it into coarse blotches; a prefiltered map averages it to its mean.
surface fine_noise(
    color a      = color(0.85, 0.80, 0.70),
    color b      = color(0.10, 0.12, 0.20),
    float freq   = 180.0,
    float Ks     = 0.1)
{
    float n = noise(P * freq);
    float m = smoothstep(0.35, 0.65, n);
    color Cd = mix(a, b, m);
    Ci = Cd * (ambient() + diffuse(N)) + Ks * specular(N, -I, 0.4);
}
