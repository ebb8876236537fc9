import mitsuba as mi, numpy as np, flip_evaluator as flip, sys
mi.set_variant('scalar_rgb')
def load(n): return np.array(mi.Bitmap(n+'.exr').convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
n=sys.argv[1]
ref=load('ref'); a=load(n)
Y=np.array([0.2126,0.7152,0.0722])
from numpy.lib.stride_tricks import sliding_window_view
def blur(x,k=7):
    p=np.pad(x,k//2,mode='edge'); return sliding_window_view(p,(k,k)).mean(axis=(2,3))
lr=blur(ref@Y); la=blur(a@Y)
rel=(la-lr)/(lr+0.01)
m=np.zeros(ref.shape,np.float32); m[...,0]=np.clip(rel*2,0,1); m[...,2]=np.clip(-rel*2,0,1)
mi.Bitmap((m*255).astype(np.uint8)).write('diff_'+n+'.png')
fm, mean, _ = flip.evaluate(ref, a, "HDR")
print(n,'flip',mean)
for thr in [0.2,0.1,0.05]:
    mask=np.abs(rel)>thr
    b=a.copy(); b[mask]=ref[mask]
    print('thr',thr,'masked %.3f'%mask.mean(),'flip %.4f'%flip.evaluate(ref,b,"HDR")[1], 'darker %.3f brighter %.3f'%((rel< -thr).mean(),(rel>thr).mean()))
