// Registration of the grid classes with MRPT's RTTI and map-definition
// registries (docs/maps.md, "Registration").
#pragma once

namespace bims::maps
{
/** Registers the three grids (and their bases) with mrpt::rtti so that
 * CArchive::ReadObject() and classFactory() know them. Idempotent and
 * thread-safe; run automatically by every grid constructor and, through
 * whole-archive linking of bims::maps, at program start, so that
 * CMultiMetricMap creation from an .ini works without calling it. */
void registerClasses();
}  // namespace bims::maps
