//! Quality measures comparing a smoothed mesh with its original: volume, discrete Gaussian
//! curvature, the paper's local error with the drifting reference vertex, and the score S(tau).
