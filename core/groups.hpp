// The Lie groups lpshoot offers. Each is a struct of static functions templated on the scalar
// (double or a Dual, so automatic differentiation flows through):
//   dim, Element<T>, Tangent<T> (R^dim, coordinates in a fixed algebra basis),
//   identity, compose, inverse, exp, log, Ad (matrix acting on algebra coordinates),
//   cast<T>(element), and matrix/hat (a faithful matrix representation, used by the tests).
// Ad*_g is Ad_g^T in these coordinates. log is a local inverse of exp near the identity.
#pragma once

#include "group_product.hpp"
#include "group_rn.hpp"
#include "group_se2.hpp"
#include "group_so2.hpp"
