// tiled_floor.sl -- square tiles with dark grout, each tile its own shade, mottled by noise:
// sharp edges and fine detail, the hardest kind of texture to see at a grazing angle.
surface tiled_floor(
    color light  = color(0.82, 0.78, 0.70),
    color dark   = color(0.45, 0.38, 0.30),
    color grout  = color(0.12, 0.11, 0.10),
    float size   = 0.5,
    float joint  = 0.06,
    float Ks     = 0.25)
{
    float x = P[0] / size;
    float z = P[2] / size;
    // Inside a tile away from its joints: 1; in the grout: 0.
    float inside = step(joint, fract(x)) * step(joint, fract(z));
    float shade = cellnoise(point(floor(x), 0.0, floor(z)));
    float mottle = 0.75 + 0.5 * noise(P * 9.0);
    color Cd = mix(grout, mix(dark, light, shade) * mottle, inside);
    Ci = Cd * (ambient() + diffuse(N)) + Ks * specular(N, -I, 0.3);
}
