// Fetches /api/scene and, while the run is not final, polls it for changes: the server answers
// 204 (nothing new), the deltas since the revision the page has, or the full document.
// Never throws: every failure goes to onError and the next poll tries again.
import { SceneState } from './scene_state.js';

const POLL_MS = 200;
const RETRY_MS = 1000;          // after a failure (server starting or gone): try less often

export class SceneClient {
  constructor({ onScene, onError }) {
    this.onScene = onScene;
    this.onError = onError;
    this.revision = null;
    this.state = null;   // SceneState: the page's copy, which deltas update
    this.stopped = false;
  }

  start() { this.poll(); }

  stop() { this.stopped = true; }

  async poll() {
    if (this.stopped) return;
    let delay = POLL_MS;
    try {
      const document = await this.fetchScene();
      if (document) this.accept(document);
      this.onError(null);
    } catch (error) {
      this.onError(`scene update failed: ${error.message || error}; retrying`);
      delay = RETRY_MS;
    }
    if (!this.stopped) setTimeout(() => this.poll(), delay);
  }

  // The parsed document, or null when nothing changed since this.revision.
  async fetchScene() {
    const url = this.revision === null ? '/api/scene' : `/api/scene?since=${this.revision}`;
    const response = await fetch(url, { cache: 'no-store' });
    if (response.status === 204) return null;
    if (!response.ok) throw new Error(`GET ${url}: HTTP ${response.status}`);
    const document = await response.json();
    const isDelta = document?.type === 'delta' && Array.isArray(document.deltas);
    if (typeof document !== 'object' || document === null || (!document.counts && !isDelta)) {
      throw new Error(`GET ${url}: not a scene document`);
    }
    if (isDelta) return document;
    // The server may answer the full document even when nothing changed.
    if (this.revision !== null && document.revision === this.revision && !document.final) return null;
    return document;
  }

  accept(reply) {
    let document = reply;
    if (reply.type === 'delta') {
      if (!this.state || reply.from !== this.revision) {
        this.revision = null;   // out of step: the next poll loads the full document
        return;
      }
      for (const delta of reply.deltas) this.state.apply(delta);
      document = this.state.document();
    } else {
      this.state = new SceneState(reply);
    }
    this.revision = document.revision ?? null;
    if (document.final) this.stopped = true;
    this.onScene(document);
  }
}
