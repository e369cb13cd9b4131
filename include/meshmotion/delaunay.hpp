#pragma once
/// \file
/// The delaunay layer: robust predicates, Bowyer–Watson triangulation with point location,
/// and the Delaunay graph mapping of query points.

#include "meshmotion/delaunay/bowyer_watson.hpp"
#include "meshmotion/delaunay/delaunay_triangulation.hpp"
#include "meshmotion/delaunay/graph_mapping.hpp"
#include "meshmotion/delaunay/predicates.hpp"
