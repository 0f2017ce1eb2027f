// A shader whose ray count is a parameter: it must stay constant.
surface counted(int rays = 4) {
    Ci = color(occlusion(P, N, rays));
}
