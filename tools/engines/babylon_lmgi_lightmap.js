/* lmgi's lightmap in Babylon.js: a glTF loader extension that reads LMGI_lightmap (docs/api.md, "The
 * lightmap in engines"). Load this script after babylonjs.loaders.js; every glTF that uses LMGI_lightmap
 * then shows lmgi's lightmap on its materials, added to whatever lights the scene has.
 *
 * The lightmap holds irradiance E; a diffuse surface adds albedo / pi x E. Babylon's PBR material adds a
 * lightmap after the albedo (or multiplies everything by it, useLightmapAsShadowmap), so neither fits. A
 * light whose lightmapMode is LIGHTMAP_SHADOWSONLY instead adds the lightmap into diffuseBase, the sum the
 * material multiplies by its albedo: one such light (no colour of its own, no shadows) carries the
 * lightmap, and the texture's level of scale / pi turns the decoded RGBD value into E / pi (Babylon's
 * diffuse is albedo x diffuseBase, without a 1/pi). Tested by tests/test_engines.c against lmgi's frame. */
(function (BABYLON) {
    'use strict';
    const NAME = 'LMGI_lightmap';

    /* The scene's one carrier light, made on first use. */
    function carrier(scene) {
        let light = scene.getLightByName(NAME);
        if (!light) {
            light = new BABYLON.HemisphericLight(NAME, new BABYLON.Vector3(0, 1, 0), scene);
            light.diffuse = new BABYLON.Color3(0, 0, 0);
            light.specular = new BABYLON.Color3(0, 0, 0);
            light.groundColor = new BABYLON.Color3(0, 0, 0);
            light.lightmapMode = BABYLON.Light.LIGHTMAP_SHADOWSONLY;
        }
        return light;
    }

    class LmgiLightmap {
        constructor(loader) {
            this.name = NAME;
            this.enabled = loader.isExtensionUsed(NAME);
            this._loader = loader;
        }

        dispose() {
            this._loader = null;
        }

        loadMaterialPropertiesAsync(context, material, babylonMaterial) {
            return BABYLON.GLTF2.GLTFLoader.LoadExtensionAsync(context, material, NAME, (extContext, ext) => {
                if (ext.encoding !== 'RGBD')
                    throw new Error(`${extContext}/encoding: '${ext.encoding}' is not RGBD`);
                if (!(ext.scale > 0))
                    throw new Error(`${extContext}/scale: ${ext.scale} is not a positive number`);
                carrier(babylonMaterial.getScene());
                ext.lightmapTexture.nonColorData = true; /* the loader's flag: no sRGB decoding on sampling */
                return Promise.all([
                    this._loader.loadMaterialPropertiesAsync(context, material, babylonMaterial),
                    this._loader.loadTextureInfoAsync(`${extContext}/lightmapTexture`, ext.lightmapTexture, (texture) => {
                        texture.level = ext.scale / Math.PI;
                        babylonMaterial.lightmapTexture = texture;
                    }).then((texture) => {
                        /* both live in the GPU texture, which exists once loaded: set before, they are lost
                         * (and gammaSpace left true decodes the gamma twice) */
                        texture.isRGBD = true;
                        texture.gammaSpace = false;
                    }),
                ]).then(() => undefined);
            });
        }
    }

    BABYLON.GLTF2.registerGLTFExtension(NAME, true, (loader) => new LmgiLightmap(loader));
})(BABYLON);
