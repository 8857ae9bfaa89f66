// SPDX-License-Identifier: MIT
#include "surface3d/analytic.h"
