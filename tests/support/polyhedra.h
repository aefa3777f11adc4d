#pragma once

/// \file
/// \brief Display geometries of the thesis' examples, generated as cave geometry OBJ text: a
/// cube, a 10-facet "cylindrical" prism (its side walls) and the 24-facet trapezoidal
/// (deltoidal) icositetrahedron of figure 18a. Each facet is cut from its plane by all the
/// others, so the facets meet exactly; corners run counter-clockwise seen from inside.

#include <string>

namespace basalt::test {

/// \brief The cube -1..1 on every axis.
std::string cubeDisplayObj();
/// \brief The ten side walls of a decagonal prism around the Y axis (walls at distance 1 from
/// the axis, height -1..1); floor and ceiling are not screens.
std::string prismDisplayObj();
/// \brief The trapezoidal icositetrahedron: the dual of the rhombicuboctahedron, 24 kites.
std::string icositetrahedronDisplayObj();

/// \brief The same OBJ text with every `f` line's corners in the reverse order ("f 1 2 3 4"
/// becomes "f 4 3 2 1"): facets facing outward, as modelling tools export a room; other lines
/// are kept as they are.
std::string reverseFacetWinding(const std::string& obj);

}  // namespace basalt::test
