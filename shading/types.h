// types.h -- the shading language's value types.
#pragma once

namespace mpshade {

enum class ValueType { Float, Int, Color, Point, Vector, Normal, Void };

constexpr bool isTriple(ValueType t) {
    return t == ValueType::Color || t == ValueType::Point || t == ValueType::Vector ||
           t == ValueType::Normal;
}
constexpr bool isScalar(ValueType t) {
    return t == ValueType::Float || t == ValueType::Int;
}
constexpr int componentCount(ValueType t) {
    return isTriple(t) ? 3 : (t == ValueType::Void ? 0 : 1);
}
const char* typeName(ValueType t);

}  // namespace mpshade
