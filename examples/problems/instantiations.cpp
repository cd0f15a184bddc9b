// One explicit instantiation of each paper problem's flow, so that the programs and tests that
// use them do not compile the engine again (the headers declare them extern).
#include "beanie.hpp"
#include "electron.hpp"

template class lpshoot::DiscreteFlow<lpshoot::problems::Electron>;
template class lpshoot::DiscreteFlow<lpshoot::problems::BeanieFree>;
template class lpshoot::DiscreteFlow<lpshoot::problems::BeanieControl>;
