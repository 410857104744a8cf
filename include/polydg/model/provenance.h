// A model's provenance as VTU field data: how Model::write() stores it and Model::read()
// restores it, so the grid cell and the sliver rule travel with the mesh between commands.
#pragma once

#include <optional>

#include "polydg/mesh/vtu_io.h"
#include "polydg/model/model.h"

namespace polydg {

/// The field data of `p`: numbers polydg_cell_size (0 when not sliced), polydg_reference_volume
/// and polydg_sliver_fraction; text polydg_reference ("grid_cell" or "median_element") and
/// polydg_source.
VtuFieldData provenanceFieldData(const Provenance& p);

/// The provenance stored by provenanceFieldData(), or nothing if `data` lacks it or holds
/// values no polydg wrote (a non-positive or non-finite reference volume, a fraction outside
/// [0, 1], an unknown reference kind): a file without usable provenance is treated as one
/// written by another program.
std::optional<Provenance> provenanceFromFieldData(const VtuFieldData& data);

}  // namespace polydg
