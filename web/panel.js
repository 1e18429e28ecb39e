// The side panel: numbers of the last scene document, status line, live camera image.
// Numbers are written without thousands separators so tests can read them back as is.

const NONE = '–';

function text(id, value) {
  const element = document.getElementById(id);
  if (element) element.textContent = value;
}

function integer(value) {
  return Number.isFinite(value) ? String(Math.round(value)) : NONE;
}

function metres(value) {
  if (!Number.isFinite(value)) return NONE;
  if (Math.abs(value) < 0.01) return `${(value * 1000).toFixed(1)} mm`;
  if (Math.abs(value) < 1) return `${(value * 100).toFixed(2)} cm`;
  return `${value.toFixed(3)} m`;
}

function stateText(doc) {
  const state = doc.counts.state ?? null;
  if (!doc.final) return state ?? NONE;
  return state ? `${state} (final)` : 'final';
}

export function showScene(doc) {
  const counts = doc.counts;
  text('scene-source', doc.source ?? NONE);
  text('scene-name', doc.name ?? NONE);
  document.getElementById('scene-name').title = doc.name ?? '';
  text('count-frame', integer(counts.frame));
  text('count-tracked', Number.isFinite(counts.tracked) && Number.isFinite(counts.frames)
    ? `${counts.tracked} / ${counts.frames}` : NONE);
  text('count-fps', Number.isFinite(counts.fps) ? counts.fps.toFixed(1) : NONE);
  text('count-state', stateText(doc));
  for (const name of ['keyframes', 'points', 'lines', 'loops', 'relocalizations']) {
    text(`count-${name}`, integer(counts[name]));
  }
  text('count-ate', metres(doc.ground_truth?.ate_rmse_m));
  text('scene-revision', integer(doc.revision));
  showImage(doc);
}

// /api/image.jpg exists only for live runs, from their first tracked frame on. A new image is
// asked for only once the previous one has arrived, so a slow connection does not pile up
// requests.
let imageBusy = false;

function showImage(doc) {
  const image = document.getElementById('current-image');
  const live = doc.source === 'live' && doc.counts?.frame !== null && doc.counts?.frame !== undefined;
  image.hidden = !live;
  if (!live || imageBusy) return;
  imageBusy = true;
  image.onload = image.onerror = () => { imageBusy = false; };
  image.src = `/api/image.jpg?revision=${doc.revision ?? 0}`;
}

export function showError(message) {
  const status = document.getElementById('status');
  status.textContent = message ?? '';
  status.hidden = !message;
}

// Dims the toggles of layers with nothing to draw (they stay usable for when content arrives).
export function showLayerContent(drawn) {
  for (const [name, count] of Object.entries(drawn)) {
    const box = document.getElementById(`layer-${name}`);
    if (!box) continue;
    box.closest('label').classList.toggle('empty', count === 0);
    box.closest('label').title = count === 0 ? 'nothing to draw' : `${count} drawn`;
  }
}
