// SPDX-License-Identifier: MIT
#include "modules/aabb_tree.h"
