// three.js' side of bench/gltf_clients/run.sh: parses a .glb with GLTFLoader (three@0.160.0 from
// build/tools/node_modules, no GPU), counts its meshes and the bytes of their attributes and morph
// targets, and times one frame's animation update (the mixer set to each frame's time and the
// world matrices updated), averaged over 10 passes over the frames. One JSON line.
//   node bench/gltf_clients/three_load.mjs FILE.glb
import fs from 'fs';
import path from 'path';
import { pathToFileURL, fileURLToPath } from 'url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const modules = path.join(root, 'build', 'tools', 'node_modules', 'three');
const THREE = await import(pathToFileURL(path.join(modules, 'build', 'three.module.js')));
const { GLTFLoader } = await import(pathToFileURL(path.join(modules, 'examples', 'jsm', 'loaders', 'GLTFLoader.js')));

const file = process.argv[2];
const buf = fs.readFileSync(file);
const data = buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.byteLength);
const t0 = performance.now();
new GLTFLoader().parse(data, '', (gltf) => {
    const t1 = performance.now();
    let meshes = 0, bytes = 0, morphBytes = 0;
    gltf.scene.traverse((o) => {
        if (!o.isMesh)
            return;
        meshes++;
        const g = o.geometry;
        for (const k in g.attributes)
            bytes += g.attributes[k].array.byteLength;
        if (g.index)
            bytes += g.index.array.byteLength;
        for (const k in g.morphAttributes)
            for (const a of g.morphAttributes[k])
                morphBytes += a.array.byteLength;
    });
    const mixer = new THREE.AnimationMixer(gltf.scene);
    for (const clip of gltf.animations)
        mixer.clipAction(clip).play();
    const times = gltf.parser.json.scenes[0].extras.plume.frame_times;
    const t2 = performance.now();
    for (let pass = 0; pass < 10; pass++)
        for (const t of times) {
            mixer.setTime(t);
            gltf.scene.updateMatrixWorld(true);
        }
    const t3 = performance.now();
    console.log(JSON.stringify({parse_ms: t1 - t0, meshes, geometry_MB: bytes / 1e6, morph_MB: morphBytes / 1e6,
                                animate_one_frame_ms: (t3 - t2) / (10 * times.length)}));
}, (e) => { console.error('three_load: ' + e); process.exit(1); });
