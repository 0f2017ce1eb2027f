// nan_patch.sl -- a shader that produces NaN on part of the surface: sqrt and log of a
// negative number where x < 0. The engine's NaN policy zeroes such samples and counts them;
// the rest of the surface must shade as usual.
surface nan_patch(
    color Cs = color(0.7, 0.5, 0.3))
{
    float x = P[0];
    float bad = sqrt(x) + log(x) * 0.0;
    float ok = 0.5 + 0.5 * noise(P * 4.0);
    Ci = Cs * ok * (ambient() + diffuse(N)) + 0.0 * bad;
}
