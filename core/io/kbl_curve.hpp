#pragma once
/// The centre-curve convention of KBL (VDA 4964): a Segment's Center_curve is a uniform
/// B-spline given by its degree and control points only, its knots spaced 1.0 apart starting
/// at −degree, so that n control points of degree p live on [0, n − p]. Checked on the VW
/// samples (KBL 2.3 and 2.4, degree 6, 7 control points): the curve starts at the segment's
/// start node and ends at its end node to 1e-6 mm, its arc length is the Virtual_length to
/// 1e-6 relative, its end tangents are the Start_vector and End_vector, and several curves
/// of one segment follow each other end to start. World frame, millimetres.

#include "core/centerline.hpp"

#include <vector>

namespace loom {

/// The uniform B-spline of KBL: degree p (1..7), n ≥ p + 1 control points, knots −p … n.
/// Throws std::invalid_argument for a degree outside 1..7 or too few control points.
Centerline kbl_uniform_curve(int degree, std::vector<Vec3> control_points);

/// The curve as KBL centre curves of its own degree: one uniform single-span curve (degree + 1
/// control points) per knot span, in order, each exactly that span of the curve (a change
/// of basis from the span's Bézier form). kbl_uniform_curve of each gives the curve back.
std::vector<std::vector<Vec3>> kbl_uniform_spans(const Centerline& c);

}  // namespace loom
