surface s() {
    float a = 1.0
    Ci = color(a);
}
