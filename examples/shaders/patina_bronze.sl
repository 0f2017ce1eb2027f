// patina_bronze.sl -- polished bronze under a green patina that gathers in hollows and
// streaks downward; a metallic lobe tinted by the bronze and a clear lobe over the patina.
surface patina_bronze(
    color bronze    = color(0.72, 0.45, 0.20),
    color patina    = color(0.20, 0.55, 0.45),
    color crust     = color(0.12, 0.30, 0.26),
    float scale     = 3.0,
    float patinaAmount = 0.5,
    float roughness = 0.22,
    int   aoRays    = 16)
{
    point Q = P * scale;
    // Streaks: noise stretched along y, so patina runs downward.
    float streak = fbm(point(Q[0] * 4.0, Q[1] * 0.6, Q[2] * 4.0), 8);
    float ao = occlusion(P, N, aoRays);
    float cover = turbulence(Q, 8) + 0.6 * streak + 0.8 * (1.0 - ao);
    float patinaMask = smoothstep(patinaAmount - 0.1, patinaAmount + 0.1, cover);
    float crustMask = smoothstep(0.6, 0.9, turbulence(Q * 3.0 + point(1.3, 0.0, 2.9), 8))
                      * patinaMask;
    color Cp = mix(patina, crust, crustMask) * (0.85 + 0.3 * noise(Q * 18.0));
    // Bare metal is dark in diffuse light and shines in its own colour.
    color Cd = mix(bronze * 0.25, Cp, patinaMask);
    color metal = bronze * (1.0 - patinaMask) * (0.8 + 0.2 * streak);
    float clear = 0.15 * patinaMask * (1.0 - crustMask);
    Ci = Cd * (ambient() * ao + diffuse(N))
         + metal * specular(N, -I, roughness) + clear * specular(N, -I, 0.45);
}
