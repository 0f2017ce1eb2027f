// rust_over_paint.sl -- layered: glossy paint, rust breaking through where a noise mask
// says so, and dirt gathering in crevices (low occlusion).
surface rust_over_paint(
    color paint      = color(0.10, 0.30, 0.55),
    color rust       = color(0.45, 0.20, 0.07),
    color dirt       = color(0.10, 0.08, 0.05),
    float rustAmount = 0.45,
    float scale      = 2.5,
    float roughness  = 0.2,
    int   aoRays     = 12)
{
    // Layer 1: paint, a clear coat.
    float chips = turbulence(P * scale, 5);
    float rustMask = smoothstep(rustAmount - 0.05, rustAmount + 0.05, chips);
    // Layer 2: rust, rough and mottled.
    float mottle = 0.6 + 0.4 * noise(P * scale * 8.0);
    color Crust = rust * mottle;
    color Cd = mix(paint, Crust, rustMask);
    // Layer 3: dirt in crevices.
    float ao = occlusion(P, N, aoRays);
    float dirtMask = smoothstep(0.9, 0.4, ao);
    Cd = mix(Cd, dirt, dirtMask);
    // Lighting on N, not faceforward(N, I): that would make even diffuse light depend on
    // the view, and the factoring could no longer bake it into the static part.
    float gloss = (1.0 - rustMask) * (1.0 - dirtMask);
    Ci = Cd * (ambient() * ao + diffuse(N)) + gloss * 0.6 * specular(N, -I, roughness);
}
