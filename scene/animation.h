// animation.h -- keyframed values: linear between keys, held constant outside them.
#pragma once

#include <algorithm>
#include <vector>

namespace mpshade {

template <typename T>
struct Keyframes {
    std::vector<float> times;  // strictly increasing
    std::vector<T> values;

    bool empty() const { return times.empty(); }
    // More than one key with different values: the value changes over time.
    bool varies() const {
        for (size_t i = 1; i < values.size(); ++i)
            if (!(values[i] == values[0])) return true;
        return false;
    }

    T at(float t) const {
        if (times.size() == 1 || t <= times.front()) return values.front();
        if (t >= times.back()) return values.back();
        const size_t hi =
            static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
        const size_t lo = hi - 1;
        const float w = (t - times[lo]) / (times[hi] - times[lo]);
        return values[lo] * (1.0f - w) + values[hi] * w;
    }
};

}  // namespace mpshade
