// brick.sl -- running-bond bricks in (s, t) with mortar, per-brick tint and surface noise.
surface brick(
    color brickColor  = color(0.55, 0.18, 0.10),
    color mortarColor = color(0.60, 0.58, 0.55),
    float bricksU     = 8.0,
    float bricksV     = 16.0,
    float mortar      = 0.06,
    float Ks          = 0.05)
{
    float ss = s * bricksU;
    float tt = t * bricksV;
    float row = floor(tt);
    if (mod(row, 2.0) == 1.0) {
        ss += 0.5;
    }
    float brickId = cellnoise(point(floor(ss), row, 0.0));
    float fs = fract(ss);
    float ft = fract(tt);
    float inBrick = step(mortar, fs) * step(fs, 1.0 - mortar)
                  * step(mortar * 2.0, ft) * step(ft, 1.0 - mortar * 2.0);
    float grit = 0.15 * noise(P * 40.0);
    color Cb = brickColor * (0.75 + 0.5 * brickId) * (0.9 + grit);
    color Cd = mix(mortarColor * (0.9 + grit), Cb, inBrick);
    // Lighting on N, not faceforward(N, I): that would make even diffuse light depend on
    // the view, and the factoring could no longer bake it into the static part.
    Ci = Cd * (ambient() + diffuse(N)) + Ks * specular(N, -I, 0.5);
}
