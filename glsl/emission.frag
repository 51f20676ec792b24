#version 130
// Initialisation ("initialise the shooters' unshot energy E", paper 3.2): every patch starts with
// its emitted radiance as both its radiosity and its unshot radiosity. Alpha carries the
// polygon's ID + 1, which Find_Max_Energy reads to total the unshot energy per polygon.

flat in vec3 RecvEmission;
flat in float RecvId;

out vec4 NewRadiosity;
out vec4 NewUnshot;

void main()
{
    NewRadiosity = vec4(RecvEmission, RecvId + 1.0);
    NewUnshot = NewRadiosity;
}
