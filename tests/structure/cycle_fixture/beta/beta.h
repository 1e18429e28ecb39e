#pragma once
// #include "plslam/gamma/gamma.inc"  (a comment: were it read, gamma would be on the cycle)
