"""Measures Blender's area-light power-to-radiance conversion with Cycles (not a test).

    blender -b --factory-startup --python tests/blender/measure_area_light.py

A white Diffuse BSDF plane 1 m under a light, direct light only, 64 x 64
pixels, 256 samples, an orthographic camera between them looking down; the
mean of the centre pixels under an area light of power P is compared with the
same under an emissive polygon of the same shape and radiance 10, so the area
light's radiance is L = 10 x pixel_area / pixel_emissive, and L A / P its
factor. Blender 3.4.1 prints 0.24996 for a square, a scaled rectangle and a
scaled square and 0.25037 for a disk: L = P / (4 A), A with object scale.
Used by addon/geometry.py (AREA_LIGHT_FACTOR_BEFORE_4).
"""
import math
import os
import tempfile

import bpy
import numpy as np
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine='CYCLES'; sc.cycles.device='CPU'; sc.cycles.samples=256; sc.cycles.use_denoising=False
sc.render.resolution_x=sc.render.resolution_y=64
sc.view_settings.view_transform='Standard'; sc.view_settings.look='None'
w=bpy.data.worlds.new("W"); w.use_nodes=True; w.node_tree.nodes["Background"].inputs[0].default_value=(0,0,0,1); sc.world=w
sc.cycles.max_bounces=0  # direct only
def diffuse(name, c):
    m=bpy.data.materials.new(name); m.use_nodes=True; nt=m.node_tree; nt.nodes.clear()
    d=nt.nodes.new("ShaderNodeBsdfDiffuse"); d.inputs["Color"].default_value=(c,c,c,1)
    o=nt.nodes.new("ShaderNodeOutputMaterial"); nt.links.new(d.outputs[0],o.inputs[0]); return m
def emissive(name, L):
    m=bpy.data.materials.new(name); m.use_nodes=True; nt=m.node_tree; nt.nodes.clear()
    d=nt.nodes.new("ShaderNodeEmission"); d.inputs["Strength"].default_value=L
    o=nt.nodes.new("ShaderNodeOutputMaterial"); nt.links.new(d.outputs[0],o.inputs[0]); return m
me=bpy.data.meshes.new("P"); me.from_pydata([(-2,-2,0),(2,-2,0),(2,2,0),(-2,2,0)],[],[(0,1,2,3)]); me.materials.append(diffuse("D",1.0))
plane=bpy.data.objects.new("P",me); sc.collection.objects.link(plane)
cd=bpy.data.cameras.new("C"); cd.type='ORTHO'; cd.ortho_scale=1.0; cam=bpy.data.objects.new("C",cd); cam.location=(0,0,0.9); sc.collection.objects.link(cam); sc.camera=cam
def render():
    sc.render.image_settings.file_format='OPEN_EXR'; sc.render.filepath=os.path.join(tempfile.gettempdir(), 'radiosity_measure.exr')
    bpy.ops.render.render(write_still=True)
    im=bpy.data.images.load(os.path.join(tempfile.gettempdir(), 'radiosity_measure.exr')); px=np.empty(len(im.pixels),np.float32); im.pixels.foreach_get(px); bpy.data.images.remove(im)
    return px.reshape(64,64,4)[24:40,24:40,0].mean()
# reference: emissive quad 0.5x0.5 at z=1 facing down, radiance 10
qm=bpy.data.meshes.new("Q"); s=0.25
qm.from_pydata([(-s,-s,1),(-s,s,1),(s,s,1),(s,-s,1)],[],[(0,1,2,3)]); qm.materials.append(emissive("E",10.0))
q=bpy.data.objects.new("Q",qm); sc.collection.objects.link(q)
ref=render(); print("MEAS quad L=10:", ref)
bpy.data.objects.remove(q)
def light(shape, size, size_y, power, scale=(1,1,1)):
    ld=bpy.data.lights.new("L",'AREA'); ld.shape=shape; ld.size=size; ld.size_y=size_y; ld.energy=power
    lo=bpy.data.objects.new("L",ld); lo.location=(0,0,1); lo.scale=scale; sc.collection.objects.link(lo)
    v=render(); bpy.data.objects.remove(lo); bpy.data.lights.remove(ld); return v
P=10.0
for shape,size,sy,scale,area in (("SQUARE",0.5,0.5,(1,1,1),0.25),("RECTANGLE",0.25,0.5,(2,1,1),0.25),("SQUARE",0.25,0.25,(2,2,1),0.25)):
    v=light(shape,size,sy,P,scale)
    L=10.0*v/ref
    print("MEAS %s size %g x %g scale %s: pixel %.5f -> radiance %.4f; L*A/P = %.5f (1/4=0.25, 1/pi=%.5f)"%(shape,size,sy,scale,v,L,L*area/P,1/math.pi))
# disk vs equal-area square: disk of diameter d, area pi d^2/4
d=0.5; v=light("DISK",d,d,P); Adisk=math.pi*d*d/4
# reference for disk: a 64-gon emissive of radiance 10
n=64; ang=np.linspace(0,2*np.pi,n,endpoint=False); verts=[(d/2*math.cos(a),-d/2*math.sin(a),1) for a in ang]
qm2=bpy.data.meshes.new("Q2"); qm2.from_pydata(verts,[],[tuple(range(n))]); qm2.materials.append(emissive("E2",10.0))
q2=bpy.data.objects.new("Q2",qm2); sc.collection.objects.link(q2); refd=render(); bpy.data.objects.remove(q2)
L=10*v/refd; print("MEAS DISK d=0.5: pixel %.5f ref %.5f -> radiance %.4f; L*A/P = %.5f"%(v,refd,L,L*Adisk/P))
