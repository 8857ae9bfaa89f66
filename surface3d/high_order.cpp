// SPDX-License-Identifier: MIT
#include "surface3d/high_order.h"
