// sphfsi: umbrella header. Include single headers instead to keep compile times down.
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/integrators/predictor_corrector.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/kernel/gaussian.hpp>
#include <sphfsi/kernel/quintic_spline.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/neighbors/cell_list.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/scenes/solid_builders.hpp>
#include <sphfsi/solid/body.hpp>
#include <sphfsi/solid/concepts.hpp>
#include <sphfsi/solid/elastic_material.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>
#include <sphfsi/solid/updated_lagrangian.hpp>
