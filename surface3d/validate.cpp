// SPDX-License-Identifier: MIT
#include "surface3d/validate.h"
