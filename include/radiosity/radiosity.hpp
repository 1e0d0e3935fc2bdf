// The radiosity library: global illumination by the radiosity method.
// This umbrella header is the stable v1 facade: load_scene, cornell_box, solve, render,
// write_exr, write_png and version, with the types they use.
#pragma once

#include "radiosity/brdf.hpp"
#include "radiosity/common.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/io.hpp"
#include "radiosity/lightmap.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/path_tracer.hpp"
#include "radiosity/render.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"
#include "radiosity/two_pass.hpp"
#include "radiosity/version.hpp"
