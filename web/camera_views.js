// Placing the viewing camera: fit the whole map, look straight down, follow the SLAM camera.
// Works in display coordinates: the scene root is turned 180 deg about x, so a world point
// (x, y, z) is shown at (x, -y, -z) and the world's up (-y) is screen up (+Y).
import * as THREE from 'three';

export function toDisplay(x, y, z) {
  return new THREE.Vector3(x, -y, -z);
}

export class CameraViews {
  constructor(camera, controls) {
    this.camera = camera;
    this.controls = controls;
    this.centre = new THREE.Vector3();
    this.radius = 1;
  }

  // Called on every new document: only the clipping planes follow the map's size, the view stays.
  setBounds(bounds) {
    this.centre = toDisplay(bounds.centre.x, bounds.centre.y, bounds.centre.z);
    this.radius = bounds.radius;
    this.camera.near = this.radius / 1000;
    this.camera.far = this.radius * 200;
    this.camera.updateProjectionMatrix();
    this.controls.maxDistance = this.radius * 50;
  }

  // Distance at which the map fills the narrower field of view. The sphere around the
  // percentile box is loose (the box's corners are mostly empty), hence the 0.8.
  fitDistance() {
    const vertical = THREE.MathUtils.degToRad(this.camera.fov);
    const horizontal = 2 * Math.atan(Math.tan(vertical / 2) * this.camera.aspect);
    return 0.8 * this.radius / Math.sin(Math.min(vertical, horizontal) / 2);
  }

  // From behind and above the first camera (world -z and -y), looking at the map's centre.
  fit() {
    const direction = new THREE.Vector3(0, 0.6, 1).normalize();
    this.lookAt(this.centre, direction.multiplyScalar(this.fitDistance()));
  }

  // Straight down the gravity axis. The tiny offset towards screen +Z (world -z) keeps
  // OrbitControls away from its pole and puts the first camera's forward at the top of the screen.
  top() {
    const distance = this.fitDistance();
    this.lookAt(this.centre, new THREE.Vector3(0, distance, distance * 1e-4));
  }

  lookAt(target, offset) {
    this.controls.target.copy(target);
    this.camera.position.copy(target).add(offset);
    this.controls.update();
  }

  // Moves the target onto the current camera centre and the viewpoint with it, so
  // the user's angle and distance are kept.
  follow(pose) {
    if (!pose || pose.length !== 12) return;
    const target = toDisplay(pose[3], pose[7], pose[11]);
    const shift = target.clone().sub(this.controls.target);
    this.camera.position.add(shift);
    this.controls.target.copy(target);
    this.controls.update();
  }
}
