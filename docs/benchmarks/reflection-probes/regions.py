import mitsuba as mi, numpy as np
mi.set_variant('scalar_rgb')
def load(n): return np.array(mi.Bitmap(n+'.exr').convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
Y=np.array([0.2126,0.7152,0.0722])
regions={'alcoveL':(252,290,198,228),'alcoveR':(395,425,190,215),'deskside':(415,455,285,345),'floor_by_desk':(420,480,345,370),'wall':(420,480,120,160)}
names=['ref','rt8','rt8_norefl','rt8_nodn','prt16']
imgs={n:load(n)@Y for n in names}
for r,(x0,x1,y0,y1) in regions.items():
    print(r, ' '.join('%s %.4f'%(n, imgs[n][y0:y1,x0:x1].mean()) for n in names))
