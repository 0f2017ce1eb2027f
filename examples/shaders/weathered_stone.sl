// weathered_stone.sl -- layered stone: veined rock, lichen growing in patches, dust settled
// in crevices, and a thin wet film whose highlight follows the eye.
surface weathered_stone(
    color rock      = color(0.62, 0.60, 0.56),
    color veinColor = color(0.30, 0.28, 0.30),
    color lichen    = color(0.42, 0.48, 0.18),
    color dust      = color(0.55, 0.47, 0.36),
    float scale     = 2.0,
    float lichenAmount = 0.55,
    float wetness   = 0.35,
    float roughness = 0.18,
    int   aoRays    = 24)
{
    // Layer 1: the rock, two scales of 8-octave noise bending its veins.
    point Q = P * scale;
    float grain = fbm(Q * 3.0, 8);
    float warp = fbm(Q + point(grain, 0.0, -grain), 8);
    float vein = 1.0 - smoothstep(0.0, 0.12, abs(sin(Q[1] * 3.0 + 6.0 * warp)));
    color Cd = mix(rock * (0.85 + 0.3 * grain), veinColor, vein);
    // Layer 2: lichen, patchy, with its own fine mottling.
    float patches = turbulence(Q * 0.7 + point(3.1, 1.7, 0.4), 8);
    float lichenMask = smoothstep(lichenAmount - 0.08, lichenAmount + 0.08, patches);
    float mottle = 0.7 + 0.3 * noise(Q * 25.0);
    Cd = mix(Cd, lichen * mottle, lichenMask);
    // Layer 3: dust where the geometry hides the sky.
    float ao = occlusion(P, N, aoRays);
    float dustMask = smoothstep(0.85, 0.45, ao) * (1.0 - 0.5 * lichenMask);
    Cd = mix(Cd, dust, dustMask);
    // The wet film shines only on bare rock. Diffuse light on N (not faceforward(N, I)), so
    // it stays static.
    float film = wetness * (1.0 - lichenMask) * (1.0 - dustMask);
    Ci = Cd * (ambient() * ao + diffuse(N)) + film * specular(N, -I, roughness);
}
