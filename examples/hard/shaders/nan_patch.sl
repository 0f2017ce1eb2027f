// nan_patch.sl -- a shader that produces NaN on part of the surface. The builtins are
// "safe" (sqrt of a negative is 0), but an overflow is not: exp(2000 x) is infinite where
// x > 0.045, and inf - inf is NaN there. The renderers replace such samples by opaque black
// and count them; the rest of the surface must shade as usual.
surface nan_patch(
    color Cs = color(0.7, 0.5, 0.3))
{
    float big = exp(P[0] * 2000.0);
    float bad = big - big;
    float ok = 0.5 + 0.5 * noise(P * 4.0);
    Ci = Cs * ok * (ambient() + diffuse(N)) + bad;
}
