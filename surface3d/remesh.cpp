// SPDX-License-Identifier: MIT
#include "surface3d/remesh.h"
