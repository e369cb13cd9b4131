#pragma once
/// \file
/// The delaunay layer: robust predicates, Bowyer–Watson triangulation with point location.

#include "meshmotion/delaunay/bowyer_watson.hpp"
#include "meshmotion/delaunay/delaunay_triangulation.hpp"
#include "meshmotion/delaunay/predicates.hpp"
