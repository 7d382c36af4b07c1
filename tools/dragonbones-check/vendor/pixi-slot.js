// The official DragonBonesJS PixiJS 4 platform classes PixiTextureAtlasData, PixiTextureData and
// PixiSlot (its _updateFrame, _updateMesh, _updateTransformV4, _updateColor, _updateVisible and
// _updateZOrder compute what Pixi draws: mesh vertices, skinning of weighted meshes, deform
// offsets, the display transform, tint/alpha, visibility and child order), VENDORED VERBATIM
// from the compiled build
//
//   repository: github.com/DragonBones/DragonBonesJS
//   commit:     6aaa69a3293240730a11c3c1ef58eb79099bbcb1 (2018-05-16, DragonBones.VERSION "5.6.300")
//   file:       Pixi/4.x/out/dragonBones.js, lines 14961-15081 and 15312-15644
//               (compiled from Pixi/4.x/src/dragonBones/pixi/PixiTextureAtlasData.ts and
//               PixiSlot.ts)
//
// That commit's core is the code @cocos/dragonbones-js 1.0.2 ships (same statements; the fork
// only turns the const enums into objects, adds ES exports and defaults DragonBones.yDown to
// false), so these methods see the data structures they were written for (DeformVertices,
// VerticesData). No DragonBones PixiJS build matching that core is on npm (the npm
// `dragonbones-pixi` 5.6.0 is an older core with _ffdVertices/_meshData), hence the copy.
//
// Also vendored: the `__extends` helper (lines 2-11 of the same file). Dropped: each module's
// `var dragonBones;` line. Only the module wrapper is ours: the vendored IIFEs ran against a global `dragonBones`
// namespace and a global `PIXI`; here they get both as parameters (check.mjs passes a mutable
// copy of the @cocos/dragonbones-js exports and a minimal PIXI stand-in). Between the BEGIN and
// END markers the text is the upstream file's, MIT licence headers included.
export function installPixiSlot(dragonBones, PIXI) {
var __extends = (this && this.__extends) || (function () {
    var extendStatics = Object.setPrototypeOf ||
        ({ __proto__: [] } instanceof Array && function (d, b) { d.__proto__ = b; }) ||
        function (d, b) { for (var p in b) if (b.hasOwnProperty(p)) d[p] = b[p]; };
    return function (d, b) {
        extendStatics(d, b);
        function __() { this.constructor = d; }
        d.prototype = b === null ? Object.create(b) : (__.prototype = b.prototype, new __());
    };
})();
// ---- BEGIN vendored Pixi/4.x/out/dragonBones.js lines 14961-15081 ----
/**
 * The MIT License (MIT)
 *
 * Copyright (c) 2012-2018 DragonBones team and other contributors
 *
 * Permission is hereby granted, free of charge, to any person obtaining a copy of
 * this software and associated documentation files (the "Software"), to deal in
 * the Software without restriction, including without limitation the rights to
 * use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies of
 * the Software, and to permit persons to whom the Software is furnished to do so,
 * subject to the following conditions:
 *
 * The above copyright notice and this permission notice shall be included in all
 * copies or substantial portions of the Software.
 *
 * THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
 * IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS
 * FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR
 * COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER
 * IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN
 * CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
 */
(function (dragonBones) {
    /**
     * - The PixiJS texture atlas data.
     * @version DragonBones 3.0
     * @language en_US
     */
    /**
     * - PixiJS 贴图集数据。
     * @version DragonBones 3.0
     * @language zh_CN
     */
    var PixiTextureAtlasData = /** @class */ (function (_super) {
        __extends(PixiTextureAtlasData, _super);
        function PixiTextureAtlasData() {
            var _this = _super !== null && _super.apply(this, arguments) || this;
            _this._renderTexture = null; // Initial value.
            return _this;
        }
        PixiTextureAtlasData.toString = function () {
            return "[class dragonBones.PixiTextureAtlasData]";
        };
        PixiTextureAtlasData.prototype._onClear = function () {
            _super.prototype._onClear.call(this);
            if (this._renderTexture !== null) {
                // this._renderTexture.dispose();
            }
            this._renderTexture = null;
        };
        /**
         * @inheritDoc
         */
        PixiTextureAtlasData.prototype.createTexture = function () {
            return dragonBones.BaseObject.borrowObject(PixiTextureData);
        };
        Object.defineProperty(PixiTextureAtlasData.prototype, "renderTexture", {
            /**
             * - The PixiJS texture.
             * @version DragonBones 3.0
             * @language en_US
             */
            /**
             * - PixiJS 贴图。
             * @version DragonBones 3.0
             * @language zh_CN
             */
            get: function () {
                return this._renderTexture;
            },
            set: function (value) {
                if (this._renderTexture === value) {
                    return;
                }
                this._renderTexture = value;
                if (this._renderTexture !== null) {
                    for (var k in this.textures) {
                        var textureData = this.textures[k];
                        textureData.renderTexture = new PIXI.Texture(this._renderTexture, textureData.region, // No need to set frame.
                        textureData.region, new PIXI.Rectangle(0, 0, textureData.region.width, textureData.region.height), textureData.rotated // .d.ts bug
                        );
                    }
                }
                else {
                    for (var k in this.textures) {
                        var textureData = this.textures[k];
                        textureData.renderTexture = null;
                    }
                }
            },
            enumerable: true,
            configurable: true
        });
        return PixiTextureAtlasData;
    }(dragonBones.TextureAtlasData));
    dragonBones.PixiTextureAtlasData = PixiTextureAtlasData;
    /**
     * @internal
     */
    var PixiTextureData = /** @class */ (function (_super) {
        __extends(PixiTextureData, _super);
        function PixiTextureData() {
            var _this = _super !== null && _super.apply(this, arguments) || this;
            _this.renderTexture = null; // Initial value.
            return _this;
        }
        PixiTextureData.toString = function () {
            return "[class dragonBones.PixiTextureData]";
        };
        PixiTextureData.prototype._onClear = function () {
            _super.prototype._onClear.call(this);
            if (this.renderTexture !== null) {
                this.renderTexture.destroy(false);
            }
            this.renderTexture = null;
        };
        return PixiTextureData;
    }(dragonBones.TextureData));
    dragonBones.PixiTextureData = PixiTextureData;
})(dragonBones || (dragonBones = {}));
// ---- END ----
// ---- BEGIN vendored Pixi/4.x/out/dragonBones.js lines 15312-15644 ----
/**
 * The MIT License (MIT)
 *
 * Copyright (c) 2012-2018 DragonBones team and other contributors
 *
 * Permission is hereby granted, free of charge, to any person obtaining a copy of
 * this software and associated documentation files (the "Software"), to deal in
 * the Software without restriction, including without limitation the rights to
 * use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies of
 * the Software, and to permit persons to whom the Software is furnished to do so,
 * subject to the following conditions:
 *
 * The above copyright notice and this permission notice shall be included in all
 * copies or substantial portions of the Software.
 *
 * THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
 * IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS
 * FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR
 * COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER
 * IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN
 * CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
 */
(function (dragonBones) {
    /**
     * - The PixiJS slot.
     * @version DragonBones 3.0
     * @language en_US
     */
    /**
     * - PixiJS 插槽。
     * @version DragonBones 3.0
     * @language zh_CN
     */
    var PixiSlot = /** @class */ (function (_super) {
        __extends(PixiSlot, _super);
        function PixiSlot() {
            return _super !== null && _super.apply(this, arguments) || this;
        }
        PixiSlot.toString = function () {
            return "[class dragonBones.PixiSlot]";
        };
        PixiSlot.prototype._onClear = function () {
            _super.prototype._onClear.call(this);
            this._textureScale = 1.0;
            this._renderDisplay = null;
            this._updateTransform = PIXI.VERSION[0] === "3" ? this._updateTransformV3 : this._updateTransformV4;
        };
        PixiSlot.prototype._initDisplay = function (value, isRetain) {
            // tslint:disable-next-line:no-unused-expression
            value;
            // tslint:disable-next-line:no-unused-expression
            isRetain;
        };
        PixiSlot.prototype._disposeDisplay = function (value, isRelease) {
            // tslint:disable-next-line:no-unused-expression
            value;
            if (!isRelease) {
                value.destroy();
            }
        };
        PixiSlot.prototype._onUpdateDisplay = function () {
            this._renderDisplay = (this._display ? this._display : this._rawDisplay);
        };
        PixiSlot.prototype._addDisplay = function () {
            var container = this._armature.display;
            container.addChild(this._renderDisplay);
        };
        PixiSlot.prototype._replaceDisplay = function (value) {
            var container = this._armature.display;
            var prevDisplay = value;
            container.addChild(this._renderDisplay);
            container.swapChildren(this._renderDisplay, prevDisplay);
            container.removeChild(prevDisplay);
            this._textureScale = 1.0;
        };
        PixiSlot.prototype._removeDisplay = function () {
            this._renderDisplay.parent.removeChild(this._renderDisplay);
        };
        PixiSlot.prototype._updateZOrder = function () {
            var container = this._armature.display;
            var index = container.getChildIndex(this._renderDisplay);
            if (index === this._zOrder) {
                return;
            }
            container.addChildAt(this._renderDisplay, this._zOrder);
        };
        /**
         * @internal
         */
        PixiSlot.prototype._updateVisible = function () {
            this._renderDisplay.visible = this._parent.visible && this._visible;
        };
        PixiSlot.prototype._updateBlendMode = function () {
            if (this._renderDisplay instanceof PIXI.Sprite) {
                switch (this._blendMode) {
                    case 0 /* Normal */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.NORMAL;
                        break;
                    case 1 /* Add */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.ADD;
                        break;
                    case 3 /* Darken */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.DARKEN;
                        break;
                    case 4 /* Difference */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.DIFFERENCE;
                        break;
                    case 6 /* HardLight */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.HARD_LIGHT;
                        break;
                    case 9 /* Lighten */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.LIGHTEN;
                        break;
                    case 10 /* Multiply */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.MULTIPLY;
                        break;
                    case 11 /* Overlay */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.OVERLAY;
                        break;
                    case 12 /* Screen */:
                        this._renderDisplay.blendMode = PIXI.BLEND_MODES.SCREEN;
                        break;
                    default:
                        break;
                }
            }
            // TODO child armature.
        };
        PixiSlot.prototype._updateColor = function () {
            this._renderDisplay.alpha = this._colorTransform.alphaMultiplier;
            if (this._renderDisplay instanceof PIXI.Sprite || this._renderDisplay instanceof PIXI.mesh.Mesh) {
                var color = (Math.round(this._colorTransform.redMultiplier * 0xFF) << 16) + (Math.round(this._colorTransform.greenMultiplier * 0xFF) << 8) + Math.round(this._colorTransform.blueMultiplier * 0xFF);
                this._renderDisplay.tint = color;
            }
            // TODO child armature.
        };
        PixiSlot.prototype._updateFrame = function () {
            var currentVerticesData = (this._deformVertices !== null && this._display === this._meshDisplay) ? this._deformVertices.verticesData : null;
            var currentTextureData = this._textureData;
            if (this._displayIndex >= 0 && this._display !== null && currentTextureData !== null) {
                var currentTextureAtlasData = currentTextureData.parent;
                if (this._armature.replacedTexture !== null && this._rawDisplayDatas !== null && this._rawDisplayDatas.indexOf(this._displayData) >= 0) {
                    if (this._armature._replaceTextureAtlasData === null) {
                        currentTextureAtlasData = dragonBones.BaseObject.borrowObject(dragonBones.PixiTextureAtlasData);
                        currentTextureAtlasData.copyFrom(currentTextureData.parent);
                        currentTextureAtlasData.renderTexture = this._armature.replacedTexture;
                        this._armature._replaceTextureAtlasData = currentTextureAtlasData;
                    }
                    else {
                        currentTextureAtlasData = this._armature._replaceTextureAtlasData;
                    }
                    currentTextureData = currentTextureAtlasData.getTexture(currentTextureData.name);
                }
                var renderTexture = currentTextureData.renderTexture;
                if (renderTexture !== null) {
                    if (currentVerticesData !== null) {
                        var data = currentVerticesData.data;
                        var intArray = data.intArray;
                        var floatArray = data.floatArray;
                        var vertexCount = intArray[currentVerticesData.offset + 0 /* MeshVertexCount */];
                        var triangleCount = intArray[currentVerticesData.offset + 1 /* MeshTriangleCount */];
                        var vertexOffset = intArray[currentVerticesData.offset + 2 /* MeshFloatOffset */];
                        if (vertexOffset < 0) {
                            vertexOffset += 65536; // Fixed out of bouds bug. 
                        }
                        var uvOffset = vertexOffset + vertexCount * 2;
                        var scale = this._armature._armatureData.scale;
                        var meshDisplay = this._renderDisplay;
                        var textureAtlasWidth = currentTextureAtlasData.width > 0.0 ? currentTextureAtlasData.width : renderTexture.width;
                        var textureAtlasHeight = currentTextureAtlasData.height > 0.0 ? currentTextureAtlasData.height : renderTexture.height;
                        meshDisplay.vertices = new Float32Array(vertexCount * 2);
                        meshDisplay.uvs = new Float32Array(vertexCount * 2);
                        meshDisplay.indices = new Uint16Array(triangleCount * 3);
                        for (var i = 0, l = vertexCount * 2; i < l; ++i) {
                            meshDisplay.vertices[i] = floatArray[vertexOffset + i] * scale;
                            meshDisplay.uvs[i] = floatArray[uvOffset + i];
                        }
                        for (var i = 0; i < triangleCount * 3; ++i) {
                            meshDisplay.indices[i] = intArray[currentVerticesData.offset + 4 /* MeshVertexIndices */ + i];
                        }
                        for (var i = 0, l = meshDisplay.uvs.length; i < l; i += 2) {
                            var u = meshDisplay.uvs[i];
                            var v = meshDisplay.uvs[i + 1];
                            if (currentTextureData.rotated) {
                                meshDisplay.uvs[i] = (currentTextureData.region.x + (1.0 - v) * currentTextureData.region.width) / textureAtlasWidth;
                                meshDisplay.uvs[i + 1] = (currentTextureData.region.y + u * currentTextureData.region.height) / textureAtlasHeight;
                            }
                            else {
                                meshDisplay.uvs[i] = (currentTextureData.region.x + u * currentTextureData.region.width) / textureAtlasWidth;
                                meshDisplay.uvs[i + 1] = (currentTextureData.region.y + v * currentTextureData.region.height) / textureAtlasHeight;
                            }
                        }
                        this._textureScale = 1.0;
                        meshDisplay.texture = renderTexture;
                        meshDisplay.dirty++;
                        meshDisplay.indexDirty++;
                    }
                    else {
                        this._textureScale = currentTextureData.parent.scale * this._armature._armatureData.scale;
                        var normalDisplay = this._renderDisplay;
                        normalDisplay.texture = renderTexture;
                    }
                    this._visibleDirty = true;
                    return;
                }
            }
            if (currentVerticesData !== null) {
                var meshDisplay = this._renderDisplay;
                meshDisplay.texture = null;
                meshDisplay.x = 0.0;
                meshDisplay.y = 0.0;
                meshDisplay.visible = false;
            }
            else {
                var normalDisplay = this._renderDisplay;
                normalDisplay.texture = null;
                normalDisplay.x = 0.0;
                normalDisplay.y = 0.0;
                normalDisplay.visible = false;
            }
        };
        PixiSlot.prototype._updateMesh = function () {
            var scale = this._armature._armatureData.scale;
            var deformVertices = this._deformVertices.vertices;
            var bones = this._deformVertices.bones;
            var verticesData = this._deformVertices.verticesData;
            var weightData = verticesData.weight;
            var hasDeform = deformVertices.length > 0 && verticesData.inheritDeform;
            var meshDisplay = this._renderDisplay;
            if (weightData !== null) {
                var data = verticesData.data;
                var intArray = data.intArray;
                var floatArray = data.floatArray;
                var vertexCount = intArray[verticesData.offset + 0 /* MeshVertexCount */];
                var weightFloatOffset = intArray[weightData.offset + 1 /* WeigthFloatOffset */];
                if (weightFloatOffset < 0) {
                    weightFloatOffset += 65536; // Fixed out of bouds bug. 
                }
                for (var i = 0, iD = 0, iB = weightData.offset + 2 /* WeigthBoneIndices */ + bones.length, iV = weightFloatOffset, iF = 0; i < vertexCount; ++i) {
                    var boneCount = intArray[iB++];
                    var xG = 0.0, yG = 0.0;
                    for (var j = 0; j < boneCount; ++j) {
                        var boneIndex = intArray[iB++];
                        var bone = bones[boneIndex];
                        if (bone !== null) {
                            var matrix = bone.globalTransformMatrix;
                            var weight = floatArray[iV++];
                            var xL = floatArray[iV++] * scale;
                            var yL = floatArray[iV++] * scale;
                            if (hasDeform) {
                                xL += deformVertices[iF++];
                                yL += deformVertices[iF++];
                            }
                            xG += (matrix.a * xL + matrix.c * yL + matrix.tx) * weight;
                            yG += (matrix.b * xL + matrix.d * yL + matrix.ty) * weight;
                        }
                    }
                    meshDisplay.vertices[iD++] = xG;
                    meshDisplay.vertices[iD++] = yG;
                }
            }
            else if (hasDeform) {
                var isSurface = this._parent._boneData.type !== 0 /* Bone */;
                var data = verticesData.data;
                var intArray = data.intArray;
                var floatArray = data.floatArray;
                var vertexCount = intArray[verticesData.offset + 0 /* MeshVertexCount */];
                var vertexOffset = intArray[verticesData.offset + 2 /* MeshFloatOffset */];
                if (vertexOffset < 0) {
                    vertexOffset += 65536; // Fixed out of bouds bug. 
                }
                for (var i = 0, l = vertexCount * 2; i < l; i += 2) {
                    var x = floatArray[vertexOffset + i] * scale + deformVertices[i];
                    var y = floatArray[vertexOffset + i + 1] * scale + deformVertices[i + 1];
                    if (isSurface) {
                        var matrix = this._parent._getGlobalTransformMatrix(x, y);
                        meshDisplay.vertices[i] = matrix.a * x + matrix.c * y + matrix.tx;
                        meshDisplay.vertices[i + 1] = matrix.b * x + matrix.d * y + matrix.ty;
                    }
                    else {
                        meshDisplay.vertices[i] = x;
                        meshDisplay.vertices[i + 1] = y;
                    }
                }
            }
        };
        /**
         * @internal
         */
        PixiSlot.prototype._updateGlueMesh = function () {
            // TODO
        };
        PixiSlot.prototype._updateTransform = function () {
            throw new Error();
        };
        PixiSlot.prototype._updateTransformV3 = function () {
            this.updateGlobalTransform(); // Update transform.
            var transform = this.global;
            if (this._renderDisplay === this._rawDisplay || this._renderDisplay === this._meshDisplay) {
                var x = transform.x - (this.globalTransformMatrix.a * this._pivotX + this.globalTransformMatrix.c * this._pivotY);
                var y = transform.y - (this.globalTransformMatrix.b * this._pivotX + this.globalTransformMatrix.d * this._pivotY);
                this._renderDisplay.setTransform(x, y, transform.scaleX * this._textureScale, transform.scaleY * this._textureScale, transform.rotation, transform.skew, 0.0);
            }
            else {
                this._renderDisplay.position.set(transform.x, transform.y);
                this._renderDisplay.rotation = transform.rotation;
                this._renderDisplay.skew.set(transform.skew, 0.0);
                this._renderDisplay.scale.set(transform.scaleX, transform.scaleY);
            }
        };
        PixiSlot.prototype._updateTransformV4 = function () {
            this.updateGlobalTransform(); // Update transform.
            var transform = this.global;
            if (this._renderDisplay === this._rawDisplay || this._renderDisplay === this._meshDisplay) {
                var x = transform.x - (this.globalTransformMatrix.a * this._pivotX + this.globalTransformMatrix.c * this._pivotY);
                var y = transform.y - (this.globalTransformMatrix.b * this._pivotX + this.globalTransformMatrix.d * this._pivotY);
                this._renderDisplay.setTransform(x, y, transform.scaleX * this._textureScale, transform.scaleY * this._textureScale, transform.rotation, -transform.skew, 0.0);
            }
            else {
                this._renderDisplay.position.set(transform.x, transform.y);
                this._renderDisplay.rotation = transform.rotation;
                this._renderDisplay.skew.set(-transform.skew, 0.0);
                this._renderDisplay.scale.set(transform.scaleX, transform.scaleY);
            }
        };
        PixiSlot.prototype._identityTransform = function () {
            this._renderDisplay.setTransform(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0);
        };
        return PixiSlot;
    }(dragonBones.Slot));
    dragonBones.PixiSlot = PixiSlot;
})(dragonBones || (dragonBones = {}));
// ---- END ----
    return dragonBones;
}
