// The "layers" button of a 3D view's toolbar: a popup with one checkbox per named layer
// (gfx::SceneLayers), so the user hides what is in the way (the ghost board, the grid, ...).
#pragma once

#include "ui/gfx/scene_layers.h"

namespace calibench::ui {

// Draws the button (and its popup when open); true when a layer was shown or hidden.
bool LayerToggles(gfx::SceneLayers* layers);

}  // namespace calibench::ui
