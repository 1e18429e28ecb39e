// Per-point colours of the map: by height or by age. Writes linear RGB into a
// Float32Array (three.js treats vertex colours as linear and converts to sRGB on output).
import * as THREE from 'three';

// Ramps are written in sRGB, as one would pick them; stops are evenly spaced.
// Neither ramp ends in red: red/orange is kept for the current camera and the local map.
const HEIGHT_STOPS = [[0.22, 0.32, 0.70], [0.13, 0.60, 0.72], [0.35, 0.80, 0.45],
                      [0.75, 0.88, 0.25], [1.00, 0.92, 0.45]];        // low slate blue .. high yellow
const AGE_STOPS = [[0.20, 0.35, 1.00], [0.62, 0.38, 0.90], [1.00, 0.50, 0.65],
                   [1.00, 0.90, 0.25]];                                // old blue .. new yellow

const LUT_SIZE = 256;

// Interpolated once into a lookup table of linear RGB, so colouring 100k points is a table read.
function makeLut(stops) {
  const lut = new Float32Array(LUT_SIZE * 3);
  const colour = new THREE.Color();
  for (let i = 0; i < LUT_SIZE; i++) {
    const t = (i / (LUT_SIZE - 1)) * (stops.length - 1);
    const k = Math.min(Math.floor(t), stops.length - 2);
    const f = t - k;
    const a = stops[k], b = stops[k + 1];
    colour.setRGB(a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f,
                  THREE.SRGBColorSpace);
    lut[i * 3] = colour.r; lut[i * 3 + 1] = colour.g; lut[i * 3 + 2] = colour.b;
  }
  return lut;
}

const HEIGHT_LUT = makeLut(HEIGHT_STOPS);
const AGE_LUT = makeLut(AGE_STOPS);

function writeFromLut(out, i, lut, t) {
  const k = Math.round(Math.min(Math.max(t, 0), 1) * (LUT_SIZE - 1)) * 3;
  out[i * 3] = lut[k]; out[i * 3 + 1] = lut[k + 1]; out[i * 3 + 2] = lut[k + 2];
}

// q-quantile of a sorted typed array.
export function quantile(sorted, q) {
  if (sorted.length === 0) return 0;
  return sorted[Math.min(sorted.length - 1, Math.max(0, Math.round(q * (sorted.length - 1))))];
}

// Sorted values of component `axis` of xyz (optionally negated), from at most ~20k evenly
// strided points: plenty for 2 %/98 % quantiles and it keeps live rebuilds of big maps cheap.
export function sortedSample(xyz, axis, sign = 1) {
  const n = Math.floor(xyz.length / 3);
  const stride = Math.max(1, Math.ceil(n / 20000));
  const sample = new Float32Array(Math.ceil(n / stride));
  for (let i = 0, k = 0; i < n; i += stride, k++) sample[k] = sign * xyz[i * 3 + axis];
  return sample.sort();
}

// Height is -y (the world is the first camera's frame, y down). The ramp spans the
// 2nd..98th percentile so that a few outliers do not flatten everything into one colour.
export function heightColours(xyz, out) {
  const n = Math.floor(xyz.length / 3);
  const sorted = sortedSample(xyz, 1, -1);
  const low = quantile(sorted, 0.02), high = quantile(sorted, 0.98);
  const span = high - low > 1e-9 ? high - low : 1;
  for (let i = 0; i < n; i++) writeFromLut(out, i, HEIGHT_LUT, (-xyz[i * 3 + 1] - low) / span);
  return out;
}

// Age is the rank of the point id (ids grow with creation), so the ramp is uniform over points.
export function ageColours(ids, out) {
  const n = ids.length;
  const order = new Uint32Array(n);
  for (let i = 0; i < n; i++) order[i] = i;
  let ascending = true;
  for (let i = 1; i < n && ascending; i++) ascending = ids[i - 1] <= ids[i];
  if (!ascending) order.sort((a, b) => ids[a] - ids[b]);
  const scale = n > 1 ? 1 / (n - 1) : 0;
  for (let rank = 0; rank < n; rank++) writeFromLut(out, order[rank], AGE_LUT, rank * scale);
  return out;
}
