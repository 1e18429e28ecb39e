#pragma once
#include "plslam/beta/beta.h"
