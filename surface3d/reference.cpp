// SPDX-License-Identifier: MIT
#include "surface3d/reference.h"
