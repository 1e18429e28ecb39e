#pragma once
#include "plslam/alpha/alpha.h"
#include "plslam/gamma/gamma.inc"
