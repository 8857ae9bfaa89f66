// SPDX-License-Identifier: MIT
#include "surface3d/features.h"
