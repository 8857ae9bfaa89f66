// SPDX-License-Identifier: MIT
#include "surface3d/read_surface.h"
